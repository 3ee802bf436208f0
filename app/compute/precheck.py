"""The checks of a request that need the registry but no numerics, run before it is queued."""

from __future__ import annotations

from ...engine.registry import ROBOTS
from . import schemas as S
from .robot_requests import gamma_and_mode
from .synthesis import synthesis_region


def precheck(req: S.SolveRequest | S.RepeatabilityRequest | S.SynthesizeRequest) -> None:
    """The registry checks that need no numerics and that a route's model (exact for its robot:
    names, maps, the lengths of x0, target and path) cannot make: a discrete gamma's bound, a
    synthesis' box.

    Run on the event loop before a request is sent to a worker, so bad requests are answered at
    once even when every worker is busy. The workers repeat them (the plain service functions
    are complete on their own).
    """
    if req.robot.name in S.USER_ROBOT_MODELS:
        return  # (p and r follow from the definition: built and checked in a worker)
    spec = ROBOTS[req.robot.name]
    if isinstance(req, S.SynthesizeRequest):
        synthesis_region(spec, spec.build(), req)
    else:
        gamma_and_mode(spec, req)
