"""Reading a robot file (:func:`jik.engine.robot_spec.load_robot`): its bytes, its text, its data.

A robot file is JSON, or YAML (``.yaml``/``.yml``, needs PyYAML), of at most
:data:`MAX_FILE_BYTES`, UTF-8 (a byte-order mark is skipped). Its data is a few dozen numbers,
names and formulas nested a few levels deep, so it is held to :data:`MAX_DEPTH` levels and
:data:`MAX_NODES` values before anything is built from it. YAML's anchors and aliases are
refused: a robot needs none, and aliases that repeat aliases make a file of a few hundred bytes
expand to gigabytes. Every refusal is an :class:`InvalidInputError` naming the file and the
``field`` the caller gives (``"robot"``, ``"urdf_file"``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from .exceptions import InvalidInputError

#: Largest robot file read by :func:`read_robot_file` [bytes].
MAX_FILE_BYTES = 2_000_000
#: Deepest nesting of lists and mappings in a robot file (a definition needs five: the robot,
#: its augmentations, one of them, its region, a [lo, hi] pair).
MAX_DEPTH = 16
#: Most values (numbers, texts, lists, mappings) in a robot file: a path of 100 task points of
#: a 6-dimensional task needs 700.
MAX_NODES = 20_000


def read_text(path: Path, field: str, most: int) -> str:
    """The text of the file ``path`` of at most ``most`` bytes, decoded as UTF-8 (a leading
    byte-order mark skipped); else an InvalidInputError with ``field`` that names the file."""
    try:
        if path.stat().st_size > most:
            raise InvalidInputError(f"{path.name} is larger than {most} bytes", field)
        data = path.read_bytes()
    except OSError as exc:
        raise InvalidInputError(f"cannot read {path.name}: {exc.strerror}", field) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InvalidInputError(
            f"{path.name} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
            f"{exc.start}); save it as UTF-8",
            field,
        ) from None


def read_robot_file(path: Path, field: str = "robot") -> Any:
    """The data of the robot file ``path``: JSON, or YAML for a ``.yaml``/``.yml`` suffix.

    Raises
    ------
    InvalidInputError
        With ``field``: a file too large, not UTF-8, not valid JSON or YAML, nested deeper
        than :data:`MAX_DEPTH` or holding more than :data:`MAX_NODES` values, or (YAML) with
        an anchor or alias.
    """
    text = read_text(path, field, MAX_FILE_BYTES)
    if path.suffix.lower() in (".yaml", ".yml"):
        return _yaml(text, path.name, field)
    try:
        data = json.loads(text)
    except RecursionError:  # (the parser recurses per level: far past MAX_DEPTH)
        raise InvalidInputError(_too_deep(path.name), field) from None
    except ValueError as exc:  # (JSONDecodeError, or an integer of over 4300 digits)
        raise InvalidInputError(f"{path.name} is not valid JSON: {exc}", field) from None
    _check_structure(data, path.name, field)
    return data


def _too_deep(where: str) -> str:
    return f"{where}: lists and mappings nest more than {MAX_DEPTH} levels deep"


def _too_many(where: str) -> str:
    return f"{where}: more than {MAX_NODES} values; a robot file needs a few hundred"


def _check_structure(data: Any, name: str, field: str) -> None:
    """Refuse parsed data nested deeper than MAX_DEPTH or of more than MAX_NODES values (an
    iterative walk: no recursion, whatever the depth)."""
    stack, nodes = [(data, 1)], 0
    while stack:
        value, depth = stack.pop()
        nodes += 1
        if nodes > MAX_NODES:
            raise InvalidInputError(_too_many(name), field)
        if isinstance(value, dict | list):
            if depth > MAX_DEPTH:
                raise InvalidInputError(_too_deep(name), field)
            items = value.values() if isinstance(value, dict) else value
            stack.extend((v, depth + 1) for v in items)


def _yaml(text: str, name: str, field: str) -> Any:
    """YAML's data, composed by :func:`_loader`'s class, which refuses an alias, a deep or a
    large document before it is built."""
    try:
        import yaml
    except ImportError:  # PyYAML is optional
        raise InvalidInputError(
            "YAML robot files need PyYAML (pip install pyyaml); or write the robot as JSON", field
        ) from None
    try:
        return yaml.load(text, Loader=_loader(yaml, name, field))  # (a SafeLoader: plain data)
    except InvalidInputError:  # (the loader's refusals: a ValueError too)
        raise
    except (yaml.YAMLError, ValueError) as exc:  # (ValueError: an integer of over 4300 digits)
        raise InvalidInputError(f"{name} is not valid YAML: {exc}", field) from None


def _loader(yaml, name: str, field: str) -> type:
    """A ``yaml.SafeLoader`` whose composer counts the document's nodes and levels as it reads
    them and refuses an anchor or an alias, so nothing past the bounds is composed or built."""

    class RobotLoader(yaml.SafeLoader):
        depth = nodes = 0

        def compose_node(self, parent, index):
            event = self.peek_event()
            where = f"{name}, line {event.start_mark.line + 1}"
            if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None):
                raise InvalidInputError(
                    f"{where}: YAML anchors and aliases (&name, *name) are not allowed in a "
                    "robot file; write each value out",
                    field,
                )
            self.nodes += 1
            if self.nodes > MAX_NODES:
                raise InvalidInputError(_too_many(where), field)
            if not isinstance(event, yaml.CollectionStartEvent):
                return super().compose_node(parent, index)
            self.depth += 1
            try:
                if self.depth > MAX_DEPTH:
                    raise InvalidInputError(_too_deep(where), field)
                return super().compose_node(parent, index)
            finally:
                self.depth -= 1

    return RobotLoader
