"""Robots defined by data: a planar chain, a formula robot, a URDF arm or a built-in one.

:func:`robot_from_dict` validates a JSON-friendly definition, each error naming its field
(``InvalidInputError.field``, a dotted path such as ``"lengths.1"`` or ``"augmentations.0.h"``),
and returns a :class:`Robot`: a :class:`~jik.engine.registry.RobotSpec` built for it (p, r,
ranges, defaults, augmentations) and its kinematics. :func:`load_robot` reads one from a JSON or
YAML file, or names a built-in robot. The fixed catalogue ``registry.ROBOTS`` is unchanged.

A definition::

    {"name": "planar_chain", "joints": "RRR", "lengths": [1.0, 0.8, 0.6],
     "augmentations": [{"name": "e2_synthesized", "region": {"x2": [0.4, 2], "x3": [0.4, 2]}},
                       {"name": "formula", "h": "x3"}]}

with optional ``x_range`` (one [lo, hi] per variable), ``x0``, ``target``, ``path``, ``title``
(one line of at most ``robot_kinds.MAX_TITLE_CHARS`` characters, as a map's ``label``).
For p - r > 1 a formula augmentation's ``"h"`` is a list of p - r formulas (the extended inverse
of :mod:`jik.engine.extended_vector`); the E2 synthesis needs p = r + 1 and says so.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from . import robot_kinds
from .arms import ARMS
from .augmentations import AugmentingMap
from .exceptions import InvalidInputError
from .exports import call_repr
from .extended_vector import VectorExtendedInverse
from .formula_kinematics import FormulaKinematics
from .inverses import ExtendedInverse, Inverse
from .kinematics import Kinematics
from .limits import LimitsReport, check_limits, run_report
from .planar_chain import PlanarChain
from .registry import ROBOTS, RobotSpec, make_inverse
from .robot_augmentations import augmentations_from_dict
from .robot_defaults import defaults, points
from .robot_file import read_robot_file, read_text
from .robot_synthesis import arm_augmentations, missing_map
from .units import RobotUnits, robot_units
from .validation import of_type

#: The name of an E2-optimal augmenting map in a definition (``{"name": "e2_synthesized"}``).
SYNTHESIZED = "e2_synthesized"


@dataclass(frozen=True)
class Robot:
    """A robot ready to run: its spec (ranges, defaults, augmentations) and its kinematics.

    Attributes
    ----------
    spec : RobotSpec
    kinematics : Kinematics
    definition : dict
        The definition it was built from (JSON-friendly; :func:`robot_from_dict` rebuilds it),
        with the maps it was given by default (an arm's E2 synthesis around its home); a
        catalogue arm's names the arm, without the keys whose values are the catalogue's.
    map_vectors : mapping label -> tuple of AugmentingMap, or a function giving one
        For p - r > 1: the augmentations that are vectors of p - r maps (formulas, or an E2
        synthesis computed on first use).
    """

    spec: RobotSpec
    kinematics: Kinematics
    definition: dict
    map_vectors: Mapping[
        str, tuple[AugmentingMap, ...] | Callable[[], tuple[AugmentingMap, ...]]
    ] = field(default_factory=dict)

    def __repr__(self) -> str:
        """One line: name, title, p, r, the task's coordinates and the augmenting maps."""
        spec = self.spec
        return call_repr(
            "Robot",
            repr(spec.name),
            title=spec.title,
            p=spec.p,
            r=spec.r,
            task=" ".join(spec.task_names),
            # (a vector of maps, p - r > 1, is one of spec.augmentations and of map_vectors)
            maps=tuple(dict.fromkeys([*(a.name for a in spec.augmentations), *self.map_vectors])),
        )

    def __reduce__(self):
        """Pickled as its definition, which :func:`robot_from_dict` builds again (its spec holds
        functions that do not pickle): a catalogue arm by its name, a URDF by its text."""
        d = dict(self.definition)
        if "urdf_file" in d:  # (relative to a folder the copy need not see)
            del d["urdf_file"]
            d["urdf"] = self.kinematics.urdf  # type: ignore[attr-defined]
        return robot_from_dict, (d,)

    def _expanded(self) -> dict:
        """:attr:`definition` as it was built: a catalogue arm's with the catalogue's URDF, end
        link and home (:func:`_catalogue_keys_left_out` undone)."""
        name = self.definition.get("name")
        if name not in ARMS:
            return self.definition
        return {**ARMS[name].definition(), **self.definition, "name": "urdf"}

    @property
    def units(self) -> RobotUnits:
        """Its joint variables and task coordinates with their units (:mod:`jik.engine.units`),
        a URDF arm's joint names and home, and the joint limits where it has them."""
        return robot_units(self.kinematics, self.spec.task_names)

    def limits_report(self, result) -> LimitsReport | None:
        """Whether a run of this robot (a solve's or a single start's repeatability result)
        stayed within its joint limits, and its first violation; None for a robot without."""
        return run_report(self.kinematics, result)

    def inverse(
        self,
        algorithm: str = "pseudoinverse",
        augmentation: str | None = None,
        parameters: Mapping[str, object] | None = None,
        algorithm_parameters: Mapping[str, object] | None = None,
        x0=None,
    ) -> Inverse:
        """The inverse named ``algorithm`` (:func:`~jik.engine.registry.make_inverse`, with
        ``x0`` the run's start: the posture inverse's default rest for a robot without home),
        or the extended inverse (11) with one of its augmenting maps (a
        :class:`~jik.engine.extended_vector.VectorExtendedInverse` for p - r > 1)."""
        spec = self.spec
        named = {a.name for a in spec.augmentations}
        if algorithm == "extended" and augmentation == SYNTHESIZED and SYNTHESIZED not in named:
            if "home" in self._expanded():  # (an arm: its map is built here on demand)
                return self._synthesized_inverse()
        if algorithm == "extended" and not spec.augmentations:
            arm = "home" in self._expanded()
            raise InvalidInputError(missing_map(spec.name, spec.p, spec.r, arm), "augmentation")
        if algorithm == "extended" and self.map_vectors:
            name = augmentation or self.spec.default_augmentation
            if name in self.map_vectors:
                maps = self.map_vectors[name]
                maps = maps() if callable(maps) else maps  # (a synthesis runs on first use)
                return VectorExtendedInverse(self.kinematics, maps)
        return make_inverse(
            self.kinematics,
            algorithm,
            augmentation,
            parameters,
            spec=self.spec,
            algorithm_parameters=algorithm_parameters,
            x0=x0,
        )

    def _synthesized_inverse(self) -> Inverse:
        """The extended inverse of an arm's E2-optimal map (or p - r of them) over all its
        joints around its home (:func:`~jik.engine.robot_synthesis.arm_augmentations`), for an
        arm whose definition gives no map of that name: ``inverse("extended", "e2_synthesized")``
        asks for what ``{"augmentations": [{"name": "e2_synthesized"}]}`` in its definition
        gives. The synthesis is kept per process for the definition, as a definition's."""
        kin, built = self.kinematics, self._expanded()
        wanted = arm_augmentations(kin, {**built, "augmentations": [{"name": SYNTHESIZED}]})
        specs, _, vectors = augmentations_from_dict(kin, wanted, _key(built))
        if SYNTHESIZED in vectors:
            maps = vectors[SYNTHESIZED]
            return VectorExtendedInverse(kin, maps() if callable(maps) else maps)
        return ExtendedInverse(kin, specs[0].build(kin))


def _get(d: Mapping, key: str, kind: type, what: str, default: Any = None) -> Any:
    if key not in d:
        if default is None:
            raise InvalidInputError(f"{key} is required ({what})", key)
        return default
    v = d[key]
    if not isinstance(v, kind):
        raise InvalidInputError(f"{key} must be {what}, got {v!r:.80}", key)
    return v


def _kinematics(kind: str, d: Mapping, base_dir: Path | None) -> Kinematics:
    if kind == "planar_chain":
        return PlanarChain(
            _get(d, "joints", str, "a string of R and P such as 'RRR'"),
            _get(d, "lengths", list, "a list of link lengths"),
            d.get("offsets"),
            d.get("orientation", False),
        )
    if kind == "formula":
        return FormulaKinematics(
            _get(d, "variables", list, "a list of variable names"),
            _get(d, "task", list, "a list of formulas, one per task component"),
            _get(d, "parameters", dict, "a mapping of names to numbers", {}),
        )
    from .urdf import UrdfChain  # (imports nothing of yourdfpy until it builds)

    if "urdf" in d and "urdf_file" in d:
        raise InvalidInputError("give urdf (the text) or urdf_file, not both", "urdf")
    text = _urdf_file(d, base_dir) if "urdf_file" in d else _get(d, "urdf", str, "URDF text")
    return UrdfChain(
        text,
        d.get("end_link"),  # (refused by the chain if missing, with the URDF's links)
        d.get("active_joints"),
        d.get("task", "xyz"),
        _get(d, "locked", dict, "a mapping of joint names to values", {}),
        d.get("home"),
        d.get("reference"),
        d.get("base_link"),
    )


def _urdf_file(d: Mapping, base_dir: Path | None) -> str:
    """The text of ``urdf_file``, a path relative to the robot file's folder, inside it."""
    from .urdf import MAX_URDF_BYTES

    if base_dir is None:
        raise InvalidInputError(
            "urdf_file is a path relative to a robot file's folder, which robot_from_dict takes "
            "as base_dir (load_robot passes it); or give urdf, the text "
            "(pathlib.Path(file).read_text())",
            "urdf_file",
        )
    name = _get(d, "urdf_file", str, "a path relative to the robot file")
    path = (base_dir / name).resolve()
    if not path.is_relative_to(base_dir.resolve()) or not path.is_file():
        raise InvalidInputError(f"urdf_file {name!r} is not a file inside {base_dir}", "urdf_file")
    return read_text(path, "urdf_file", MAX_URDF_BYTES)


def _x_range(kin: Kinematics, d: Mapping) -> tuple[tuple[float, float], ...]:
    if "x_range" in d:
        box = points(d["x_range"], 2, "x_range")
        if box.shape != (kin.p, 2) or not np.all(box[:, 0] < box[:, 1]):
            raise InvalidInputError(
                f"x_range must be {kin.p} pairs [lo, hi] with lo < hi", "x_range"
            )
        return tuple((float(a), float(b)) for a, b in box)
    limits = getattr(kin, "limits", None)
    if limits is not None:
        return tuple(limits)
    if isinstance(kin, PlanarChain):
        return tuple(
            (-math.pi, math.pi) if rev else (-float(length), float(length))
            for rev, length in zip(kin.revolute, kin.lengths, strict=True)
        )
    return ((-math.pi, math.pi),) * kin.p


def _key(d: Mapping) -> str:
    """What a robot's synthesized maps are kept under: its definition without its maps."""
    return json.dumps(
        {k: v for k, v in d.items() if k != "augmentations"}, sort_keys=True, default=str
    )


def robot_from_dict(d: Mapping, base_dir: str | Path | None = None) -> Robot:
    """Build and validate a robot from its definition (see the module docstring).

    Parameters
    ----------
    d : mapping
        ``{"name": kind, ...}`` with kind ``"planar_chain"``, ``"formula"``, ``"urdf"``, or a
        built-in robot (``registry.ROBOTS``; its parameters under ``"parameters"``; ``title``,
        ``x_range``, ``x0``, ``target`` and ``path``, given, replace its defaults).
    base_dir : path, optional
        The folder of the robot file: only then may a URDF be given as ``urdf_file``.

    Raises
    ------
    InvalidInputError
        With ``field`` the dotted path of the offending entry.
    """
    if not isinstance(d, Mapping):
        raise InvalidInputError("a robot must be a mapping with a 'name'", "name")
    kind = d.get("name")
    if not isinstance(kind, str) or kind not in {*robot_kinds.KINDS, *ROBOTS, *ARMS}:
        raise InvalidInputError(
            f"name must be one of {sorted(robot_kinds.KINDS)}, a catalogue arm {sorted(ARMS)} "
            f"or a built-in robot {sorted(ROBOTS)}, got {kind!r:.80}",
            "name",
        )
    allowed = robot_kinds.keys(kind) | ({"parameters"} if kind in ROBOTS else set())
    if unknown := set(d) - allowed:
        key = sorted(map(str, unknown))[0]
        raise InvalidInputError(
            f"unknown key {key!r} for a {kind} robot; known: {sorted(allowed)}", key
        )
    if "title" in d:  # (one line: shown in the page, a command's output, a CSV's header)
        robot_kinds.one_line(d["title"], "title")
    if kind in ROBOTS:
        base = ROBOTS[kind]
        try:
            kin = base.build(**_get(d, "parameters", dict, "a mapping of parameters", {}))
        except InvalidInputError as exc:  # (a parameter's field, within the definition)
            if exc.field and not exc.field.startswith("parameters"):
                exc.field = f"parameters.{exc.field}"
            raise
        spec = base
        if {"title", "x_range", "x0", "target", "path"} & set(d):  # (else the built-in itself)
            box = _x_range(kin, d) if "x_range" in d else base.x_range
            x0, target, path = defaults(kin, d, box, base)
            kin.start = tuple(x0)  # (where its syntheses hold the joints outside their box)
            title = d.get("title", base.title)  # (checked above)
            spec = replace(spec, title=title, x_range=box, default_x0=x0, default_target=target)
            spec = replace(spec, default_path=path)
        extra, _, _ = augmentations_from_dict(kin, d.get("augmentations", []), _key(d))
        spec = replace(spec, augmentations=(*base.augmentations, *extra)) if extra else spec
        return Robot(spec, kin, dict(d))
    if kind in ARMS:  # the catalogue's URDF, end link and home, with the definition's keys
        d = {**ARMS[kind].definition(), **{k: v for k, v in d.items() if k != "name"}}
        kin = _kinematics("urdf", d, None)
        kin.name = kind  # type: ignore[misc]  # (messages name the arm, not its kinematics' kind)
    else:
        kin = _kinematics(kind, d, None if base_dir is None else Path(base_dir))
    if kind in ARMS or (kind == "urdf" and "home" in d):  # an arm around its home
        d = {**d, "augmentations": arm_augmentations(kin, d)}
    if "limits" in d:  # (a planar chain or a formula robot: a URDF's come from its joints)
        kin.joint_limits = check_limits(d["limits"], kin.p)
    box = _x_range(kin, d)
    x0, target, path = defaults(kin, d, box)
    kin.start = tuple(x0)  # (where its syntheses hold the joints outside their box, homeless)
    augmentations, region, vectors = augmentations_from_dict(
        kin, d.get("augmentations", []), _key(d)
    )
    title = d.get("title", kind.replace("_", " "))  # (checked above)
    task_names = {
        "planar_chain": ("x", "y", "phi")[: kin.r],
        "formula": tuple(f"y{i + 1}" for i in range(kin.r)),
        "urdf": tuple(getattr(kin, "task_names", ())),
    }.get(kind, tuple(getattr(kin, "task_names", ())))
    spec = RobotSpec(
        name=kind,
        title=title,
        description=ARMS[kind].description
        if kind in ARMS
        else f"{title}: a {kind} robot defined by data",
        equation="(4)",
        p=kin.p,
        r=kin.r,
        variable_names=tuple(kin.variable_names),
        task_names=tuple(task_names),
        parameters=(),
        vector_parameters=(),
        factory=lambda: kin,
        default_x0=x0,
        default_target=target,
        default_path=path,
        x_range=box,
        augmentations=augmentations,
        default_augmentation=augmentations[0].name if augmentations else "",
        functional_region=region,
    )
    return Robot(spec, kin, _catalogue_keys_left_out(kind, d), vectors)


def _catalogue_keys_left_out(kind: str, d: Mapping) -> dict:
    """The definition ``d`` of a robot of ``kind`` as :attr:`Robot.definition` keeps it: a
    catalogue arm's by the arm's name, without the keys whose values are the catalogue's (its
    URDF text, end link, home), so that :func:`robot_from_dict` rebuilds the same arm."""
    if kind not in ARMS:
        return dict(d)
    own = ARMS[kind].definition()  # (repr: a value may be an ndarray, a home)
    return {"name": kind} | {k: v for k, v in d.items() if repr(own.get(k)) != repr(v)}


def load_robot(source: str | Path) -> Robot:
    """A robot from a JSON or YAML file (``.yaml``/``.yml``, needs PyYAML; read by
    :func:`~jik.engine.robot_file.read_robot_file`: UTF-8, bounded in size and nesting, no YAML
    aliases), or a built-in name."""
    wanted = "a file's path or a robot's name (a dict: robot_from_dict)"
    path = Path(of_type(source, (str, PathLike), "robot", wanted))
    if not path.is_file():
        if str(source) in ROBOTS or str(source) in ARMS:
            return robot_from_dict({"name": str(source)})
        raise InvalidInputError(
            f"robot {str(source)!r} is neither a file nor a built-in robot "
            f"({sorted(ROBOTS)}) or catalogue arm ({sorted(ARMS)})",
            "robot",
        )
    data = read_robot_file(path)
    return robot_from_dict(data, base_dir=path.parent)
