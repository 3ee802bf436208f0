"""Requests to engine calls: solve, its batches, and repeatability (``solve_batch_json``,
``repeatability_request``: a request model in, a response out, :class:`RequestError` naming the
field of a refusal; run in the workers by :class:`jik.app.compute.pool.ComputePool`), and the
checks of a request made before it is queued (:func:`precheck`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ...engine.exceptions import JikError
from ...engine.limits import robot_limits
from ...engine.registry import ROBOTS, RobotSpec
from ...engine.repeatability import repeatability, repeatable
from ...engine.solve_rules import refused_starts
from ...engine.solver import solve_batch as engine_solve_batch
from ...engine.units import norm_unit, robot_units
from . import schemas as S
from .documents import limits_document, nullable, solve_response_json
from .exceptions import RequestError
from .robot_requests import check_length, gamma_and_mode, request_robot
from .schemas.algorithms import parameters_of, used
from .schemas.wording import without_field
from .synthesis import synthesis_region


def precheck(req: S.SolveRequest | S.RepeatabilityRequest | S.SynthesizeRequest) -> None:
    """The registry checks that need no numerics and that a route's model (exact for its robot)
    cannot make: a discrete gamma's bound, a synthesis' box. Run on the event loop before a
    request is queued, so that a bad one is answered at once even when every worker is busy;
    the workers repeat them."""
    if req.robot.name in S.USER_ROBOT_MODELS:
        return  # (p and r follow from the definition: built and checked in a worker)
    spec = ROBOTS[req.robot.name]
    if isinstance(req, S.SynthesizeRequest):
        synthesis_region(spec, spec.build(), req)
    else:
        gamma_and_mode(spec, req)


@dataclass
class _Setup:
    """Everything a run needs, validated against the registry: the robot, its inverse of the
    request's algorithm, the engine's keywords of the run (``gamma``, ``mode``, ``tol``,
    ``max_iterations``) and the fields every run's response starts with (the robot, algorithm,
    parameters the inverse used, map, mode and gamma)."""

    spec: RobotSpec
    kinematics: Any
    inverse: Any
    run: dict[str, Any]
    head: dict[str, Any]


def _setup(req: S.SolveRequest | S.RepeatabilityRequest) -> _Setup:
    if req.algorithm == "extended" and used(req.algorithm_parameters):
        raise RequestError(
            "algorithm_parameters",
            "the extended inverse takes none (its augmenting map's parameters go in augmentation)",
        )
    try:
        built = request_robot(
            req.robot, req.augmentation, [req.algorithm], req.algorithm_parameters, req.x0
        )
    except MemoryError:  # (a worker's limit: the robot, or the map synthesized for it)
        if req.augmentation is None:
            raise RequestError("robot", "building the robot ran out of memory") from None
        raise RequestError(
            "augmentation",
            "building the augmenting map ran out of memory; ask for a lower degree or a "
            "smaller region",
        ) from None
    (inverse,) = built.inverses
    gamma, mode = gamma_and_mode(built.spec, req)
    aug = built.augmentation
    head = {
        "robot": built.robot.model_dump(mode="json"),
        "algorithm": inverse.name,
        "algorithm_parameters": parameters_of(inverse),
        "augmentation": None if aug is None else aug.model_dump(mode="json"),
        "mode": mode,
        "gamma": float(gamma),
    }
    run = {"gamma": gamma, "mode": mode, "tol": req.tolerance, "max_iterations": req.max_iterations}
    return _Setup(built.spec, built.kinematics, inverse, run, head)


#: The engine's arguments that are a request's fields (a run's, a synthesis'), by its names.
_ENGINE_FIELDS = (
    *("x0", "target", "gamma", "tolerance", "max_iterations", "path", "cycles", "mode"),
    *("region", "fixed"),
)
_REQUEST_NAMES = {"tol": "tolerance", "y_d": "target"}


def engine_error(exc: JikError) -> RequestError:
    """An engine error as a RequestError at the request's name of the field the engine's error
    carries (:attr:`InvalidInputError.field <jik.engine.exceptions.InvalidInputError>`:
    ``tol`` is ``tolerance``, ``path.1`` ``path[1]``; a singular start's is ``x0``); an
    error about no field of the request at ``request``, in the engine's words."""
    field = getattr(exc, "field", None) or ""
    head, dot, tail = field.partition(".")
    name = _REQUEST_NAMES.get(head, head)
    if name not in _ENGINE_FIELDS:
        return RequestError("request", str(exc))
    return RequestError(name + dot + tail, without_field(str(exc), field))


def batch_key(req: S.SolveRequest) -> str:
    """Requests with equal keys can share one batched engine call: their x0 apart, except
    for a posture inverse without a rest, whose rest may be the run's start."""
    rest = req.algorithm_parameters is not None and req.algorithm_parameters.rest is not None
    own_start = req.algorithm == "posture" and not rest
    exclude = (
        {"target"}
        | (set() if own_start else {"x0"})
        | ({"augmentation"} if req.algorithm == "pseudoinverse" else set())
    )
    return req.model_dump_json(exclude=exclude)


def solve_batch_json(reqs: list[S.SolveRequest]) -> list[bytes | RequestError]:
    """Solve requests sharing one :func:`batch_key` in ONE batched engine call, each response
    as its JSON bytes (:func:`solve_response_json`).

    Each member is validated on its own (lengths, singular start): a bad member gets its
    :class:`RequestError` in its slot and does not affect the others.
    """
    if not reqs:
        return []
    if len({batch_key(r) for r in reqs}) != 1:
        raise ValueError("solve_batch_json needs requests with equal batch keys")
    try:
        setup = _setup(reqs[0])
    except RequestError as exc:
        return [exc] * len(reqs)
    out: list[bytes | RequestError | None] = [None] * len(reqs)
    ok: list[int] = []
    starts = [r.x0 or setup.spec.default_x0 for r in reqs]
    targets = [r.target or setup.spec.default_target for r in reqs]
    for i in range(len(reqs)):
        try:
            check_length(setup.spec, starts[i], "x0", "p")
            check_length(setup.spec, targets[i], "target")
            setup.kinematics.check_target(targets[i], "target")
            ok.append(i)
        except RequestError as exc:
            out[i] = exc
        except JikError as exc:
            out[i] = engine_error(exc)
    if ok:
        x0 = np.array([starts[i] for i in ok], dtype=float)
        y_d = np.array([targets[i] for i in ok], dtype=float)
        refused = refused_starts(setup.inverse, x0)
        for k, why in refused.items():
            out[ok[k]] = RequestError("x0", why)
        keep = np.array([k for k in range(len(ok)) if k not in refused], dtype=int)
        if keep.size:
            try:
                batch = engine_solve_batch(
                    setup.inverse, x0[keep], y_d[keep], **setup.run, record=True
                )
            except JikError as exc:
                err = engine_error(exc)
                for k in keep:
                    out[ok[k]] = err
            else:
                for j, k in enumerate(keep):
                    out[ok[k]] = solve_response_json(setup, batch[j])
    return cast(list[bytes | RequestError], out)  # every slot was filled above


def repeatability_request(req: S.RepeatabilityRequest) -> S.RepeatabilityResponse:
    """The closed path of ``req`` driven ``req.cycles`` times (Table 1); drift per cycle."""
    setup = _setup(req)
    start = req.x0 or setup.spec.default_x0
    try:
        path = setup.spec.default_loop() if req.path is None else req.path
    except JikError as exc:  # (a robot without a closed path of its own)
        raise engine_error(exc) from None
    check_length(setup.spec, start, "x0", "p")
    for i, pt in enumerate(path):
        check_length(setup.spec, pt, f"path[{i}]")
    x0 = np.array(start, dtype=float)
    if refused := refused_starts(setup.inverse, x0[None]):
        raise RequestError("x0", refused[0])
    try:
        res = repeatability(
            setup.inverse,
            x0,
            np.array(path, dtype=float),
            cycles=req.cycles,
            **setup.run,
            record=robot_limits(setup.kinematics) is not None,  # (limits: check whole legs)
        )
    except JikError as exc:
        raise engine_error(exc) from None
    drift = np.asarray(res.drift, dtype=float)
    unit = norm_unit(robot_units(setup.kinematics).x)  # (the drift's, in the sentences)
    return S.RepeatabilityResponse(
        **setup.head,
        cycles=req.cycles,
        x0=x0.tolist(),
        targets=np.asarray(res.targets, dtype=float).tolist(),
        legs=nullable(res.legs),
        cycle_end=nullable(res.cycle_end),
        drift=nullable(drift),
        max_drift=nullable(np.max(drift)),  # (null when a cycle's drift is not finite)
        repeatable=bool(res.success) and repeatable(drift) is True,
        success=bool(res.success),
        message=cast(str, res.message),  # one start configuration: one message
        stopped_at=None if res.success or res.stopped is None else nullable(res.stopped),
        findings=[S.Sentence.model_validate(f._asdict()) for f in res.findings(unit)],
        **limits_document(setup.kinematics, res),
    )
