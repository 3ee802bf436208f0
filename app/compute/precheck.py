"""The checks of a request that need the registry but no numerics, run before it is queued."""

from __future__ import annotations

from ...engine.exceptions import InvalidInputError
from ...engine.registry import ROBOTS
from . import schemas as S
from .exceptions import RequestError
from .robot_requests import check_configuration, check_task_point, gamma_and_mode
from .synthesis import synthesis_region


def precheck(req: S.SolveRequest | S.RepeatabilityRequest | S.SynthesizeRequest) -> None:
    """The registry checks that need no numerics (names, lengths, discrete gamma).

    Run on the event loop before a request is sent to a worker, so bad requests are answered at
    once even when every worker is busy. The workers repeat them (the plain service functions
    are complete on their own).
    """
    if req.robot.name in S.USER_ROBOT_MODELS:
        return  # (p and r follow from the definition: built and checked in a worker)
    spec = ROBOTS.get(req.robot.name)
    if spec is None:
        raise RequestError(
            "robot.name", f"unknown robot {req.robot.name!r}; choose one of {sorted(ROBOTS)}"
        )
    if isinstance(req, S.SynthesizeRequest):
        synthesis_region(spec, req)
        return
    if req.algorithm == "extended" and req.augmentation is not None:
        try:
            spec.augmentation(req.augmentation.name)
        except InvalidInputError as exc:
            raise RequestError("augmentation.name", str(exc)) from None
    check_configuration(spec, req.x0)
    if isinstance(req, S.SolveRequest):
        check_task_point(spec, req.target, "target")
    else:
        for i, pt in enumerate(req.path):
            check_task_point(spec, pt, f"path[{i}]")
    gamma_and_mode(spec, req)
