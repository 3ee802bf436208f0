"""The dashboard's state: every control, validated against the registry and the engine.

A change (:func:`updated_state`) is a patch of state fields or of control keys
(:func:`jik.app.dashboard.controls.expand`); each refusal names its field
(:attr:`jik.engine.exceptions.InvalidInputError.field`). :func:`cache_key` and :func:`runs_key`
say what a run depends on (gamma only rescales theta in continuous mode, see
:mod:`jik.app.dashboard.results`).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from jik.app.dashboard.controls import MAX_DASHBOARD_CYCLES, MODES, expand
from jik.engine.exceptions import InvalidInputError
from jik.engine.registry import ROBOTS, robot_spec
from jik.engine.repeatability import MAX_PATH_POINTS
from jik.engine.validation import count, positive

ALGORITHMS = ("pseudoinverse", "extended")
#: One colour per algorithm, used in the scene and in every plot.
COLORS = {"pseudoinverse": "#d62728", "extended": "#1f77b4"}
LABELS = {"pseudoinverse": "pseudoinverse J^P# (8)", "extended": "extended Jacobian J^E# (11)"}
DEFAULT_ROBOT = "manipulator2"


@dataclass(frozen=True)
class DashboardState:
    """Every control of the dashboard (JSON-friendly)."""

    robot: str
    robot_parameters: dict
    augmentation: str
    augmentation_parameters: dict
    gamma: float
    mode: str
    x0: tuple[float, ...]
    task: str  # "path": closed path driven ``cycles`` times; "target": one solve
    target: tuple[float, ...]
    path: tuple[tuple[float, ...], ...]
    cycles: int
    tolerance: float = 1e-10

    def as_dict(self) -> dict:
        return {
            "robot": self.robot,
            "robot_parameters": {
                k: list(v) if isinstance(v, tuple | list) else v
                for k, v in self.robot_parameters.items()
            },
            "augmentation": self.augmentation,
            "augmentation_parameters": dict(self.augmentation_parameters),
            "gamma": self.gamma,
            "mode": self.mode,
            "x0": list(self.x0),
            "task": self.task,
            "target": list(self.target),
            "path": [list(p) for p in self.path],
            "cycles": self.cycles,
            "tolerance": self.tolerance,
        }


def default_state(robot: str = DEFAULT_ROBOT) -> DashboardState:
    """The registry's defaults for ``robot``."""
    spec = robot_spec(robot)
    aug = spec.augmentation(None)
    # A platform (the unicycle) starts with the paper's experiment of sec. 6.2: one target.
    closed = bool(spec.default_path) and not hasattr(spec.build(), "path")
    params: dict[str, object] = {p.name: p.default for p in spec.parameters}
    params.update({v.name: tuple(v.default) for v in spec.vector_parameters})
    return DashboardState(
        robot=spec.name,
        robot_parameters=params,
        augmentation=aug.name,
        augmentation_parameters={p.name: p.default for p in aug.parameters},
        gamma=float(spec.default_gamma),
        mode=spec.default_mode,
        x0=tuple(float(v) for v in spec.default_x0),
        task="path" if closed else "target",
        target=tuple(float(v) for v in spec.default_target),
        path=tuple(tuple(float(v) for v in p) for p in spec.default_path),
        cycles=3 if closed else 1,
    )


def updated_state(state: DashboardState, patch: Mapping[str, object]) -> DashboardState:
    """Apply a partial change and validate the result against the registry.

    ``patch`` is keyed by state fields or by control keys (:func:`.controls.expand`:
    ``{"x0.1": 0.4}``, ``{"path": "1, 1; 1, 2"}``). Changing ``robot`` starts from that robot's
    defaults; changing ``augmentation`` resets its parameters to their defaults. Nested
    parameter dicts are merged.

    Raises
    ------
    InvalidInputError
        Unknown keys, or any value the registry or the engine rejects; its ``field`` names the
        field (a dotted path).
    """
    patch = expand(state, patch)
    known = set(DashboardState.__dataclass_fields__)
    unknown = set(patch) - known
    if unknown:
        raise InvalidInputError(
            f"unknown dashboard field(s) {sorted(unknown)}; known: {sorted(known)}",
            sorted(unknown)[0],
        )
    if "robot" in patch and patch["robot"] != state.robot:
        if not isinstance(patch["robot"], str) or patch["robot"] not in ROBOTS:
            raise InvalidInputError(
                f"unknown robot {patch['robot']!r}; choose one of {sorted(ROBOTS)}", "robot"
            )
        state = default_state(str(patch["robot"]))
    if "augmentation" in patch and patch["augmentation"] != state.augmentation:
        with _field("augmentation"):
            aug = robot_spec(state.robot).augmentation(str(patch["augmentation"]))
        state = replace(
            state,
            augmentation=aug.name,
            augmentation_parameters={p.name: p.default for p in aug.parameters},
        )
    values: dict = {}
    for key, value in patch.items():
        if key in ("robot", "augmentation"):
            continue
        if key in ("robot_parameters", "augmentation_parameters"):
            if not isinstance(value, Mapping):
                raise InvalidInputError(f"{key} must be an object of parameters", key)
            value = {**getattr(state, key), **dict(value)}
        values[key] = value
    return validate(replace(state, **values))


@contextlib.contextmanager
def _field(name: str):
    """Name ``name`` as the field of an :class:`InvalidInputError` raised within that names
    none (the registry's and the engine's validators name it only in their message)."""
    try:
        yield
    except InvalidInputError as exc:
        if exc.field is None:
            exc.field = name
        raise
    except (TypeError, ValueError) as exc:  # a value of the wrong type (a list for a number)
        raise InvalidInputError(f"{name}: {exc}", name) from None


def validate(state: DashboardState) -> DashboardState:
    """Check every field through the registry and the engine's validators; normalise types.
    Each error names its field (:attr:`InvalidInputError.field`)."""
    spec = robot_spec(state.robot)
    given, given_aug = state.robot_parameters, state.augmentation_parameters
    scalars, vectors = {}, {}
    for p in spec.parameters:
        with _field(f"robot_parameters.{p.name}"):
            scalars[p.name] = p.check(given.get(p.name, p.default))
    for v in spec.vector_parameters:
        with _field(f"robot_parameters.{v.name}"):
            vectors[v.name] = v.check(given.get(v.name, v.default))
    unknown = set(given) - set(scalars) - set(vectors)
    if unknown:
        name = sorted(unknown)[0]
        raise InvalidInputError(f"{spec.name} has no parameter {name!r}",
                                f"robot_parameters.{name}")  # fmt: skip
    with _field("robot_parameters"):
        kin = spec.build(**scalars, **vectors)
    with _field("augmentation"):
        aug = spec.augmentation(state.augmentation)
    aug_params = {}
    for p in aug.parameters:
        with _field(f"augmentation_parameters.{p.name}"):
            aug_params[p.name] = p.check(given_aug.get(p.name, p.default))
    with _field("x0"):
        x0 = kin.check(state.x0, "x0")
        if x0.ndim != 1:
            raise InvalidInputError(f"x0 must be one configuration of length {kin.p}")
    with _field("target"):
        target = kin.check_task(state.target, "target")
        if target.ndim != 1:
            raise InvalidInputError(f"target must be one task point of length {kin.r}")
    if state.task not in ("path", "target"):
        raise InvalidInputError(f"task must be 'path' or 'target', got {state.task!r}", "task")
    with _field("path"):
        path = kin.check_task(state.path, "path") if len(state.path) else np.zeros((0, kin.r))
        if state.task == "path" and (path.ndim != 2 or len(path) < 1):
            raise InvalidInputError("a closed-path task needs at least one path point")
        if len(path) > MAX_PATH_POINTS:
            raise InvalidInputError(
                f"path has {len(path)} points; at most {MAX_PATH_POINTS} allowed"
            )
    if state.mode not in MODES:
        raise InvalidInputError(f"mode must be one of {list(MODES)}, got {state.mode!r}", "mode")
    with _field("gamma"):
        gamma = positive(state.gamma, "gamma")
        if state.mode == "discrete" and gamma >= 2:
            raise InvalidInputError(f"gamma must be < 2 in discrete mode, got {gamma:g}")
    with _field("cycles"):
        cycles = count(state.cycles, "cycles", 1, MAX_DASHBOARD_CYCLES)
    with _field("tolerance"):
        tolerance = positive(state.tolerance, "tolerance")
    return DashboardState(
        robot=spec.name,
        robot_parameters={**scalars, **vectors},
        augmentation=aug.name,
        augmentation_parameters=aug_params,
        gamma=gamma,
        mode=state.mode,
        x0=tuple(float(v) for v in x0),
        task=state.task,
        target=tuple(float(v) for v in target),
        path=tuple(tuple(float(v) for v in p) for p in path),
        cycles=cycles,
        tolerance=tolerance,
    )


def cache_key(state: DashboardState, algorithm: str) -> str:
    d = state.as_dict()
    if algorithm == "pseudoinverse":
        d.pop("augmentation"), d.pop("augmentation_parameters")
    if state.mode == "continuous":
        d.pop("gamma")
    return json.dumps(d, sort_keys=True)


def runs_key(state: DashboardState) -> tuple[str, ...]:
    """Everything the runs of both algorithms depend on, up to the scale of theta.

    Two states with the same key have the same configurations along the same legs (in
    continuous mode gamma only divides theta, see the module's docstring).
    """
    return tuple(cache_key(state, a) for a in ALGORITHMS)
