"""The request examples of the OpenAPI document, one per robot and route, made from the engine's
defaults so that they cannot drift from the robots (:func:`example`).

Each per-robot request model carries its robot's example (``json_schema_extra``, filled in
when the document is made) and each route lists every robot's (``Body(openapi_examples=...)``):
Swagger UI's "Try it out" starts from the first, so it sends a body the server accepts.
``tests/app/test_examples_api.py`` posts every one of them.
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Callable
from typing import Any

import numpy as np

from ....engine import robot_kinds
from ....engine.arms import ARMS
from ....engine.registry import ALGORITHMS, ROBOTS, RobotSpec
from ....engine.robot_spec import robot_from_dict
from .robots import ROBOT_NAMES

#: The routes whose bodies have examples, by the name :func:`example` takes.
ROUTES = ("solve", "repeatability", "synthesize", "kinematics", "atlas")
#: Starts of an atlas example: a job of a few seconds.
ATLAS_STARTS = 16
#: The robot of the routes' examples of each algorithm: the paper's Table 1 robot.
ALGORITHMS_ROBOT = "manipulator2"


@functools.cache
def _robot(name: str) -> tuple[dict[str, Any], RobotSpec, Any]:
    """The robot ``name`` as a request gives it (a catalogue robot with its default parameters,
    an arm with its task, a URDF robot as the Panda's definition, another kind from the examples
    of :mod:`jik.engine.robot_kinds`), its spec (a user robot's as its build makes it: its x0,
    target and path) and its kinematics."""
    if name in ROBOTS:
        spec = ROBOTS[name]
        robot: dict[str, Any] = {"name": name}
        robot |= {p.name: p.default for p in spec.parameters}
        robot |= {v.name: list(v.default) for v in spec.vector_parameters}
        return robot, spec, spec.build(**{k: v for k, v in robot.items() if k != "name"})
    if name in ARMS:
        robot = {"name": name, "task": ARMS[name].task}
    elif name == "urdf":
        robot = ARMS["panda"].definition()
    else:
        fields = robot_kinds.KINDS[name]
        robot = {"name": name, **{f.name: f.example for f in fields if f.example is not None}}
    built = robot_from_dict(robot)
    return robot, built.spec, built.kinematics


def _loop(name: str) -> list[list[float]]:
    """An atlas's loop as the dashboard drives it: from k(x0) through the robot's closed path
    (its starts then lie on the self-motion curve through x0, the default reference)."""
    _, spec, kin = _robot(name)
    home = kin.forward(np.asarray(spec.default_x0, dtype=float))
    path = [list(point) for point in spec.default_path]
    return path if np.allclose(home, path[0]) else [home.tolist(), *path]


@functools.cache
def example(route: str, name: str) -> dict[str, Any]:
    """A body of ``route`` (one of :data:`ROUTES`) for the robot ``name`` that the server
    accepts: the robot's defaults, the route's other fields left at theirs."""
    robot, spec, _ = _robot(name)
    x0 = list(spec.default_x0)
    path = [list(point) for point in spec.default_path]
    if route == "solve":
        target = list(spec.default_target)
        return {"robot": robot, "algorithm": "pseudoinverse", "x0": x0, "target": target}
    if route == "repeatability":
        return {"robot": robot, "algorithm": "pseudoinverse", "x0": x0, "path": path, "cycles": 2}
    if route == "synthesize":  # (a user robot's map: h the last joint variable)
        amap = {"name": "formula", "h": spec.variable_names[-1]}
        if name in ROBOTS:
            amap = {"name": spec.default_augmentation}
        return {"robot": robot, "method": "evaluate", "augmentation": amap}
    if route == "kinematics":
        return {"robot": robot, "x": x0}
    if route == "atlas":
        return {"robot": robot, "path": _loop(name), "starts": ATLAS_STARTS}
    raise ValueError(f"no example for route {route!r}; one of {ROUTES}")


def schema_examples(route: str, name: str) -> Callable[[dict[str, Any]], None]:
    """``json_schema_extra`` of the request model of ``route`` for robot ``name``: its example,
    made when the document is (building a user robot takes a fraction of a second)."""

    def extra(schema: dict[str, Any]) -> None:
        schema["examples"] = [copy.deepcopy(example(route, name))]

    return extra


def openapi_examples(route: str) -> dict[str, dict[str, Any]]:
    """``Body(openapi_examples=...)`` of ``route``: the example of every robot a request may
    name, by its name."""
    out = {}
    for name in ROBOT_NAMES:
        out[name] = {"summary": _robot(name)[1].title, "value": copy.deepcopy(example(route, name))}
    if route in ("solve", "repeatability") and ALGORITHMS_ROBOT in out:
        out |= _algorithm_examples(route)
    return out


def _algorithm_examples(route: str) -> dict[str, dict[str, Any]]:
    """A run of :data:`ALGORITHMS_ROBOT` by each other algorithm, with its scalar parameters at
    the engine's defaults (:data:`jik.engine.registry.ALGORITHMS`) and, for the extended
    inverse, the robot's default map."""
    out = {}
    base = example(route, ALGORITHMS_ROBOT)
    spec = ROBOTS[ALGORITHMS_ROBOT]
    for name, algorithm in ALGORITHMS.items():
        if name == base["algorithm"]:
            continue
        body = {**copy.deepcopy(base), "algorithm": name}
        if name == "extended":
            body["augmentation"] = {"name": spec.default_augmentation}
        if algorithm.parameters:
            body["algorithm_parameters"] = {p.name: p.default for p in algorithm.parameters}
        out[f"{ALGORITHMS_ROBOT}, {name}"] = {
            "summary": f"{spec.title}, {name}: {algorithm.description}",
            "value": body,
        }
    return out
