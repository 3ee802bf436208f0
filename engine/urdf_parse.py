"""URDF text to a yourdfpy model, safely: bounded, UTF-8, no DTD or entities, no meshes read.

yourdfpy (a maintained URDF library; viser's URDF support builds on it) parses the robot's
elements; it is imported when a URDF robot is built, so the rest of the engine works without it
(``pip install 'jik-lab[urdf]'``).

Safety: the text is bounded in size, must be (or declare) UTF-8 or ASCII, and is parsed by lxml
with defusedxml's settings (no DTD, no entity expansion, no network; a document type
declaration, the door to entity expansion and external entities, is refused). Meshes are never
loaded, nor their paths resolved: a reference of any form is skipped with a note
(:func:`mesh_note`). A joint naming a link the URDF does not define is refused.
"""

from __future__ import annotations

import io
import logging
import re

from jik import install_hint

from .exceptions import InvalidInputError
from .robot_kinds import one_line_fault

#: Largest URDF text accepted [bytes].
MAX_URDF_BYTES = 1_000_000


def _yourdfpy():
    try:
        import yourdfpy
    except ImportError:  # the `urdf` extra is not installed
        raise InvalidInputError(
            f"URDF robots need the yourdfpy package: {install_hint('urdf')}"
        ) from None
    # yourdfpy logs each text it cannot parse as an ERROR ("Using different parsing approach."),
    # which a server printed for every bad URDF a user sent: parse_urdf reports it, in words
    # naming the field, to whoever sent it.
    logging.getLogger("yourdfpy").setLevel(logging.CRITICAL)
    return yourdfpy


def _etree():
    """lxml's etree (yourdfpy's XML library, installed with it)."""
    try:
        from lxml import etree
    except ImportError:  # the `urdf` extra is not installed
        raise InvalidInputError(
            f"URDF robots need the yourdfpy package: {install_hint('urdf')}"
        ) from None
    return etree


def mesh_note(model, field: str = "urdf") -> str:
    """A note on the URDF's mesh references, which jik never reads (empty when there are none).

    Meshes only draw a robot; its kinematics is the joints'. No path is resolved or opened,
    so a reference of any form (relative, ``package://``, ``file:///``, a URL) is skipped.
    """
    names = sorted(
        {
            str(v.geometry.mesh.filename)
            for link in model.robot.links
            for v in (*link.visuals, *link.collisions)
            if v.geometry is not None and v.geometry.mesh is not None
        }
    )
    if not names:
        return ""
    return (
        f"{field}: {len(names)} mesh file reference(s) skipped, never read (jik computes "
        f"kinematics only), e.g. {names[0][:120]!r}"
    )


#: Encodings a URDF may declare: its text reaches the parser as UTF-8 bytes, and any other
#: declared encoding would make the parser read those bytes as something else (UTF-7 turns
#: ``+ADw-!DOCTYPE`` into a document type declaration that no text check sees).
ENCODINGS = ("utf-8", "utf8", "us-ascii", "ascii")
_DECLARATION = re.compile(rb"""^<\?xml[^>]*?\bencoding\s*=\s*["']([^"']*)["']""")


def _hardened_parse(data: bytes, field: str):
    """The XML tree of ``data`` by lxml with defusedxml's semantics: no DTD (internal or
    external), no entity expansion, no network; the declared encoding UTF-8 or ASCII."""
    etree = _etree()
    match = _DECLARATION.match(data.removeprefix(b"\xef\xbb\xbf").lstrip())
    if match and match.group(1).decode("ascii", "replace").lower() not in ENCODINGS:
        raise InvalidInputError(
            f"{field}: the URDF declares encoding={match.group(1).decode('ascii', 'replace')!r}; "
            "only UTF-8 (or ASCII) is accepted",
            field,
        )
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
        remove_blank_text=True,
    )
    try:
        tree = etree.fromstring(data, parser=parser).getroottree()
    except etree.XMLSyntaxError as exc:
        raise InvalidInputError(f"{field}: not a valid URDF (XML: {exc.msg})", field) from None
    info = tree.docinfo
    if info.doctype or info.internalDTD is not None or info.externalDTD is not None:
        raise InvalidInputError(f"{field}: a URDF with a DOCTYPE (DTD) is refused", field)
    if any(isinstance(e, etree._Entity) for e in tree.iter()):
        raise InvalidInputError(f"{field}: a URDF with entity references is refused", field)
    return tree.getroot()


def _check_tree(root, field: str) -> None:
    """Refuse what yourdfpy would read silently or with a message about its own code: a root
    other than ``<robot>``, two links or two joints of one name, a joint without its parent or
    child link, a link that is the child of two joints (a URDF is a tree) and a joint's origin,
    axis or limit whose numbers are not numbers or not as many as the spec says (yourdfpy
    drops a fourth number of an origin, and names no joint for ``lower="zz"``)."""
    if root.tag != "robot":
        raise InvalidInputError(f"{field}: the root element is <{root.tag}>, not <robot>", field)
    for kind in ("link", "joint"):
        seen: set[str | None] = set()
        for element in root.iterfind(kind):
            if (name := element.get("name")) in seen:
                raise InvalidInputError(f"{field}: two {kind}s are named {name!r}", field)
            if name is not None and (fault := one_line_fault(name)):  # (&#10; is a line break)
                raise InvalidInputError(
                    f"{field}: a {kind}'s name must be one line of printable text, got {fault} "
                    f"of {name!a:.80}",
                    field,
                )
            seen.add(name)
    parent_joint: dict[str, str] = {}
    for joint in root.iterfind("joint"):
        name = joint.get("name")
        for role in ("parent", "child"):
            if joint.find(role) is None or joint.find(role).get("link") is None:
                raise InvalidInputError(
                    f'{field}: joint {name!r} has no <{role} link="..."/>', field
                )
        child = joint.find("child").get("link")
        if child in parent_joint:
            raise InvalidInputError(
                f"{field}: link {child!r} is the child of two joints, {parent_joint[child]!r} "
                f"and {name!r} (a URDF is a tree)",
                field,
            )
        parent_joint[child] = name
        for tag, attr, n in _JOINT_NUMBERS:
            element = joint.find(tag)
            value = None if element is None else element.get(attr)
            if value is not None and not _numbers(value, n):
                raise InvalidInputError(
                    f"{field}: joint {name!r} has {tag} {attr}={value!r}, not "
                    + ("a number" if n == 1 else f"{n} numbers"),
                    field,
                )


#: A joint's numeric attributes: (element, attribute, how many numbers).
_JOINT_NUMBERS = (
    ("origin", "xyz", 3),
    ("origin", "rpy", 3),
    ("axis", "xyz", 3),
    *(("limit", attr, 1) for attr in ("lower", "upper", "effort", "velocity")),
)


def _numbers(text: str, n: int) -> bool:
    """Whether ``text`` is ``n`` numbers separated by white space (as the URDF spec writes
    them; inf and nan are numbers here, their meaning is judged later)."""
    parts = text.split()
    try:
        [float(v) for v in parts]
    except ValueError:
        return False
    return len(parts) == n


def parse_urdf(text, field: str = "urdf"):
    """Parse URDF text with yourdfpy (no meshes loaded); a ``yourdfpy.URDF``.

    The text is parsed once with hardened settings (:func:`_hardened_parse`); yourdfpy reads the
    tree serialised back from that parse, which holds no DTD, entity or processing instruction.

    Raises
    ------
    InvalidInputError
        Not a string, over ``MAX_URDF_BYTES``, a declared encoding other than UTF-8, a DTD or
        entity, not a URDF (:func:`_check_tree`); the message names ``field``.
    """
    if not isinstance(text, str) or not text.strip():
        raise InvalidInputError(f"{field} must be the text of a URDF file", field)
    data = text.encode("utf-8")
    if len(data) > MAX_URDF_BYTES:
        raise InvalidInputError(
            f"{field}: URDF too large ({len(data)} bytes; at most {MAX_URDF_BYTES})", field
        )
    if re.search(rb"<!\s*(DOCTYPE|ENTITY)", data, re.IGNORECASE):
        raise InvalidInputError(f"{field}: a URDF with a DOCTYPE or ENTITY is refused", field)
    root = _hardened_parse(data, field)
    _check_tree(root, field)
    clean = _etree().tostring(root, encoding="utf-8")
    yourdfpy = _yourdfpy()
    try:
        model = yourdfpy.URDF.load(
            io.BytesIO(clean),
            build_scene_graph=False,
            load_meshes=False,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
        )
    except KeyError as exc:  # an element without an attribute yourdfpy reads
        raise InvalidInputError(
            f"{field}: not a valid URDF (an element lacks its {exc} attribute)", field
        ) from None
    except Exception as exc:  # yourdfpy raises whatever its XML walk meets
        raise InvalidInputError(f"{field}: not a valid URDF ({exc})", field) from None
    if model.robot is None or not model.robot.links:
        raise InvalidInputError(f"{field}: the URDF has no links", field)
    links = {link.name for link in model.robot.links}
    for joint in model.robot.joints:
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in links:
                raise InvalidInputError(
                    f"{field}: joint {joint.name!r} names {role} link {link!r}, which the URDF "
                    "does not define",
                    field,
                )
    return model
