"""schemathesis hooks of ``jik bench fuzz`` and its CI test: what the OpenAPI document cannot say.

The document gives every field's type, range and length, per robot (:mod:`jik.app.compute.schemas`).
A few rules tie fields together and no JSON Schema states them; a generated *positive* case that
breaks one is dropped here, because the server rightly refuses it (each refusal is tested case by
case in tests/app/test_errors.py, test_synthesize.py and test_sessions.py):

- a box's bounds: ``lo < hi``; a variable is in the box or fixed, not both, and some variable
  is left for the box; ``e2_variational`` synthesizes h on a box of 2 or 3 variables, so it
  takes no ``augmentation``;
- ``e2_total_degree`` takes any number of box variables and no ``augmentation``; its Sobol
  rule has a power of two of nodes, at least twice the basis' unknowns (at most 4000);
- a kernel frame (``frame_axes``) is p - r distinct joints, for p - r >= 2 only;
- discrete mode (asked for, or the robot's default) needs ``gamma < 2``;
- an ``augmentation`` goes with the extended inverse: a run or atlas of other algorithms alone
  takes none;
- the chosen inverse must be defined at ``x0`` (the engine says so: a singular start, by the
  server's own test);
- a pose task's target or path point has rotation coordinates at most pi long (the principal
  log never exceeds it: the engine's own check, ``check_target``);
- a user robot (``planar_chain``, ``formula``, ``urdf``) is a definition: its formulas'
  grammar, its URDF text, lengths one per joint, and what follows from them (p and r, so the
  lengths of ``x0``, ``target`` and ``path``; the variables of a map's box) no JSON Schema can
  state. A positive case with one is kept only if the server's own building of the robot
  (:func:`jik.app.compute.robot_requests.request_robot`) and its checks take it; as for the sessions
  below, what the fuzzing tests there is that whatever the schema takes is served without a
  5xx and that every response matches the document;
- an atlas's path must start where the self-motion curve can be traced (the server plans it:
  the check is the server's own planner);
- a dashboard change is checked against the session's robot (its parameters' names, its maps,
  its vectors' lengths): one that names no robot depends on a state the generator does not
  know, and one that does is kept only if the dashboard's model takes it on that robot's
  defaults. (For the sessions' routes this check is the server's own: what the fuzzing tests
  there is that whatever the model takes the route serves, without a 5xx, and that every
  response matches the document.)

The sessions' operations get, in their positive cases, the id of a live session (one shared,
made again when a case has deleted it or it expired; a new one for each ``DELETE``), so that they
reach the sessions' code instead of answering 404.

Every case also has its work capped (cycles, iterations, path points, grid and node counts,
coordinates and boxes within +-3, where the unicycle's quadrature stays small, and the posture
inverse's gain), so that the run measures the API, not the machine: the time and memory limits
have tests of their own.
"""

from __future__ import annotations

import math
import os

import httpx
import numpy as np
from pydantic import ValidationError

try:  # (schemathesis loads this module, and brings hypothesis)
    import schemathesis
    from hypothesis import strategies as st
except ImportError as exc:
    raise ImportError(
        f"{exc}: jik bench fuzz needs the test extra, pip install -e '.[test]'"
    ) from exc

from ...app.compute import schemas as S
from ...app.compute.atlas_plan import AtlasLimits, planned
from ...app.compute.atlas_schemas import AtlasRequest
from ...app.compute.exceptions import RequestError
from ...app.compute.requests import _setup
from ...app.compute.robot_requests import check_length, request_robot
from ...app.compute.synthesis import synthesis_region
from ...app.dashboard.model import default_state, updated_state
from ...app.dashboard.patch import StatePatch, patch_of
from ...engine.exceptions import InvalidInputError, JikError
from ...engine.registry import ROBOTS
from ...engine.robot_synthesis import TOTAL_DEGREE, TOTAL_NODES
from ...engine.solve_rules import refused_starts
from ...engine.synthesis_nd import MAX_UNKNOWNS
from ...engine.total_degree import basis_size

#: Caps on the fields that size the work (and on the robot parameters that do: the unicycle's
#: horizon T sizes its quadrature; T = 19.7 with 300 steps needed 1.7 GB).
WORK_CAPS = {
    "cycles": 2,
    "max_iterations": 300,
    "degree": 6,
    "nodes": 4,
    "grid": 9,
    "starts": 16,
    "qmc_nodes": 1024,
}
ROBOT_CAPS = {"T": 2 * math.pi}
MAX_PATH = 4
#: Paths of an atlas's family (shifts, scales) sent.
MAX_FAMILY = 2


#: Largest |coordinate| of a start, target or path point sent (the unicycle's controls of
#: amplitude 10 took over a minute a solve).
MAX_COORDINATE = 3.0
#: Largest path scale of an atlas sent (a Gen3's default path scaled 54 times lies far out of
#: reach: runs of seconds each, whose atlas job took the workers from the cases after it).
MAX_SCALE = 3.0
#: The posture inverse's gain sent (its pull toward the rest posture, up to the engine's 100 per
#: unit of path, drives the unicycle's controls far beyond +-3 within one leg).
MAX_GAIN = 1.0


def _clamped(v):
    if isinstance(v, list):
        return [_clamped(u) for u in v]
    if isinstance(v, float | int) and not isinstance(v, bool):
        return type(v)(max(-MAX_COORDINATE, min(MAX_COORDINATE, v)))
    return v


def _capped(body: dict) -> dict:
    body = dict(body)
    for name, cap in WORK_CAPS.items():
        if isinstance(body.get(name), int | float) and not isinstance(body[name], bool):
            body[name] = min(body[name], cap)
    for name in ("path", "shifts", "scales"):  # (an atlas: paths x starts x cycles x legs)
        if isinstance(body.get(name), list):
            body[name] = body[name][: MAX_PATH if name == "path" else MAX_FAMILY]
    for name in ("x0", "target", "path", "reference"):
        if name in body:
            body[name] = _clamped(body[name])
    if isinstance(body.get("scales"), list):
        body["scales"] = [
            min(v, MAX_SCALE) if isinstance(v, float | int) and not isinstance(v, bool) else v
            for v in body["scales"]
        ]
    for name in ("region", "fixed"):  # (a box of the unicycle's lambdas over +-100 took 20 s)
        if isinstance(body.get(name), dict):
            body[name] = {k: _clamped(v) for k, v in body[name].items()}
    augmentation = body.get("augmentation")
    if isinstance(augmentation, dict) and isinstance(augmentation.get("degree"), int):
        body["augmentation"] = {
            **augmentation,
            "degree": min(augmentation["degree"], WORK_CAPS["degree"]),
        }
    region = augmentation.get("region") if isinstance(augmentation, dict) else None
    if isinstance(region, dict) and len(region) > 3:  # (a region of any type is generated)
        # a total-degree synthesis' work grows as C(n + d, d)^2: total degree 2 over 4-16 joints
        body["augmentation"] = {**body["augmentation"], "degree": 2}
    params = body.get("algorithm_parameters")
    if isinstance(params, dict) and isinstance(params.get("gain"), int | float):
        body["algorithm_parameters"] = {**params, "gain": min(params["gain"], MAX_GAIN)}
    robot = body.get("robot")
    if isinstance(robot, dict):
        body["robot"] = {
            k: min(v, ROBOT_CAPS[k]) if k in ROBOT_CAPS and isinstance(v, float) else v
            for k, v in robot.items()
        }
    return body


def _user_robot_ok(body: dict, path: str) -> bool:
    """Whether the server builds the user robot of ``body`` and takes its lengths (see the
    module's docstring)."""
    try:
        if path == "/atlas":
            return _atlas_ok(body)
        if path == "/synthesize":
            req = S.SynthesizeRequest.model_validate(body)
            evaluate = req.method == "evaluate"
            robot = request_robot(req.robot, req.augmentation, with_map=evaluate)
            spec = robot.spec
            if req.method == "e2_total_degree":
                _, region, _ = synthesis_region(spec, robot.kinematics, req)
                return _total_degree_ok(body, len(region), spec.p, spec.r)
            if not _frame_ok(body.get("frame_axes"), spec.p, spec.r):
                return False
            if (spec.p != spec.r + 1 and not evaluate) or (evaluate and req.augmentation is None):
                return False
            _, region, _ = synthesis_region(spec, robot.kinematics, req)
            return len(region) >= 2 or evaluate
    except (RequestError, JikError, ValidationError):
        return False
    return _run_ok(body, path)


def _total_degree_ok(body: dict, d: int, p: int, r: int) -> bool:
    """The rules of a total-degree synthesis of ``d`` variables (see the module docstring)."""
    nodes, degree = int(body.get("qmc_nodes", TOTAL_NODES)), int(body.get("degree") or TOTAL_DEGREE)
    unknowns = basis_size(d, degree)
    return (
        d >= 1
        and not body.get("augmentation")
        and _frame_ok(body.get("frame_axes"), p, r)
        and not nodes & (nodes - 1)
        and unknowns <= MAX_UNKNOWNS
        and nodes >= 2 * unknowns
    )


def _frame_ok(axes, p: int, r: int) -> bool:
    """A kernel frame's joints: none, or p - r >= 2 distinct joints of the robot."""
    return axes is None or (p - r >= 2 and len(set(axes)) == len(axes) == p - r and max(axes) <= p)


def _synthesis_ok(body: dict) -> bool:
    spec = ROBOTS[body["robot"]["name"]]
    if not _frame_ok(body.get("frame_axes"), spec.p, spec.r):
        return False
    fixed = body.get("fixed") or {}
    if body.get("method") == "e2_total_degree":
        try:
            req = S.SynthesizeRequest.model_validate(body)
            _, region, _ = synthesis_region(spec, spec.build(), req)
        except (RequestError, JikError, ValidationError):
            return False
        return _total_degree_ok(body, len(region), spec.p, spec.r)
    synthesis = body.get("method") == "e2_variational"
    if body.get("region") is None:  # (the default box: the last variables not fixed)
        size = min(2 if synthesis else 3, sum(n not in fixed for n in spec.variable_names))
        return size >= (2 if synthesis else 1) and not (synthesis and body.get("augmentation"))
    region = body["region"]
    if any(not lo < hi for lo, hi in region.values()) or set(region) & set(fixed):
        return False
    return not synthesis or (2 <= len(region) <= 3 and not body.get("augmentation"))


def _run_ok(body: dict, path: str) -> bool:
    """Whether the server takes the run of ``body`` (a /solve or /repeatability request): its
    own checks (robot, map, algorithm parameters, gamma's rule, lengths) and start."""
    try:
        model = S.SolveRequest if path == "/solve" else S.RepeatabilityRequest
        run = model.model_validate(body)
        setup = _setup(run)
        spec = setup.spec  # (a start, target or path not given: the robot's)
        x0 = list(spec.default_x0) if run.x0 is None else run.x0
        check_length(spec, x0, "x0", "p")
        if isinstance(run, S.RepeatabilityRequest):
            points = spec.default_loop() if run.path is None else run.path
        else:
            points = [list(spec.default_target) if run.target is None else run.target]
        for i, point in enumerate(points):
            check_length(spec, point, f"path[{i}]")
        setup.kinematics.check_target(points, "path")  # (a pose's rotation within pi)
        # (the server's own test of a singular start, which a nearly singular J J^T fails)
        setup.inverse.matrix(np.asarray(x0, dtype=float))
        if refused_starts(setup.inverse, np.asarray([x0], dtype=float)):
            return False
    except (RequestError, JikError, ValidationError):
        return False
    return True


def _change_ok(body: dict) -> bool:
    change = body.get("state", body)
    if not isinstance(change, dict) or "robot" not in change:
        return False
    try:
        state = default_state(change["robot"])
        updated_state(state, patch_of(StatePatch.model_validate(change)))
    except (InvalidInputError, ValidationError):
        return False
    return True


def _atlas_ok(body: dict) -> bool:
    try:
        planned(AtlasRequest.model_validate(body), AtlasLimits())
    except (JikError, RequestError, ValidationError):
        return False
    return True


def _positive_case_ok(case) -> bool:
    body = case.body
    if not isinstance(body, dict):
        return True
    path = case.operation.path
    robot = body.get("robot")
    if isinstance(robot, dict) and robot.get("name") in S.USER_ROBOT_MODELS:
        return _user_robot_ok(body, path)
    if path == "/synthesize":
        return _synthesis_ok(body)
    if path in ("/solve", "/repeatability"):
        return _run_ok(body, path)
    if path == "/atlas" and case.method == "POST":
        return _atlas_ok(body)
    if path.startswith("/api/sessions") and case.method == "POST" and not path.endswith("/atlas"):
        return _change_ok(body)  # (a session's atlas takes no state: any valid body is kept)
    return True


#: The server under test (:func:`jik.benchmarks.harness.bench_fuzz.run_fuzz` names it).
SERVER = os.environ.get("JIK_FUZZ_SERVER", "")


class _Sessions:
    """Live dashboard sessions of the server under test, for the sessions' operations."""

    def __init__(self) -> None:
        self._shared: str | None = None

    def _new(self) -> str | None:
        try:
            answer = httpx.post(f"{SERVER}/api/sessions", json={}, timeout=30)
        except httpx.HTTPError:
            return None
        return answer.json()["id"] if answer.status_code == 201 else None  # (503: all in use)

    def shared(self) -> str | None:
        """The shared session, made again if a case deleted it or it expired."""
        if self._shared is not None:
            try:
                gone = httpx.get(f"{SERVER}/api/sessions/{self._shared}", timeout=30)
            except httpx.HTTPError:
                return None
            if gone.status_code == 200:
                return self._shared
        self._shared = self._new()
        return self._shared

    def for_case(self, case) -> None:
        """Give a positive case of a session's operation a live session's id."""
        path = case.operation.path
        if not SERVER or "{session_id}" not in path:
            return
        session = self._new() if case.method == "DELETE" else self.shared()
        if session is not None:
            case.path_parameters = {**(case.path_parameters or {}), "session_id": session}


SESSIONS = _Sessions()


@schemathesis.hook
def before_generate_case(context, strategy: st.SearchStrategy) -> st.SearchStrategy:
    def fit(case):
        if isinstance(case.body, dict):
            case.body = _capped(case.body)
        return case

    def keep(case) -> bool:
        return not _positive(case) or _positive_case_ok(case)

    def live(case):
        if _positive(case):
            SESSIONS.for_case(case)
        return case

    return strategy.map(fit).filter(keep).map(live)


def _positive(case) -> bool:
    meta = case.meta
    return meta is None or meta.generation.mode.is_positive
