"""``jik solve`` and ``jik repeatability``: a robot from a file or by name, through the engine.

``--robot`` is a JSON or YAML robot file (:func:`jik.engine.robot_spec.load_robot`) or the name of
a built-in robot. Vectors are comma-separated numbers or constant formulas (``0, 0, pi/2``),
paths are points separated by ``;`` (``1,1; 1,2; 0,2``). Engine alone: no web package, and the
engine itself is imported only when a command runs (``jik --help`` and ``jik serve`` stay light).
``--json`` prints the engine result's ``as_dict()`` (its names: ``y_d`` the target, ``nit``, ...)
with the robot's title, its notes and its joint-limit report.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from typing import TYPE_CHECKING

from .algorithm_options import (
    ALGORITHM_NAMES,
    add_algorithm_parameter_options,
    add_run_options,
    algorithm_parameters,
    refuse_unused_options,
    run_settings,
)

if TYPE_CHECKING:
    from ..engine.robot_spec import Robot


def _split(text: str, sep: str) -> list[str]:
    """``text`` split at ``sep`` outside parentheses (atan2(a, b) stays whole)."""
    parts, depth, start = [], 0, 0
    for i, c in enumerate(text):
        depth += (c == "(") - (c == ")")
        if c == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    return [*parts, text[start:]]


def parse_vector(text: str, option: str) -> list[float]:
    """``"0, 0, pi/2"`` -> [0.0, 0.0, 1.5707963267948966]; each entry a constant formula."""
    from ..engine.exceptions import InvalidInputError
    from ..engine.formula import parse_formula

    if not text.strip():
        raise InvalidInputError(f"{option} is empty: give numbers 'a, b, ...'", option)
    out = []
    for i, part in enumerate(_split(text, ",")):
        value = parse_formula(part.strip(), {}, f"{option}[{i}]")
        out.append(float(value))  # (a constant: the grammar admits no name here)
    return out


def parse_path(text: str, option: str) -> list[list[float]]:
    """``"1,1; 1,2; 0,2"`` -> [[1, 1], [1, 2], [0, 2]]; a trailing ``;`` ends the path, an empty
    point elsewhere is refused (naming it)."""
    return [parse_vector(p, f"{option}[{i}]") for i, p in enumerate(point_texts(text))]


def point_texts(text: str) -> list[str]:
    """A path's text split into its points at ';' (outside parentheses); a trailing ';' ends
    the path, an empty point elsewhere stays (for its parser to refuse)."""
    points = _split(text, ";")
    if len(points) > 1 and not points[-1].strip():
        points.pop()
    return points


#: The built-in robots' and the catalogue arms' names (the engine's; a test checks they agree).
BUILT_IN_ROBOTS = ("manipulator1", "manipulator2", "unicycle")
CATALOGUE_ARMS = ("panda", "iiwa14", "gen3", "ur5e")


def add_robot_option(p: argparse.ArgumentParser, **kwargs) -> None:
    """--robot: a robot file or a built-in robot's or catalogue arm's name."""
    p.add_argument(
        "--robot",
        help=f"a robot file (.json, .yaml), a built-in robot ({', '.join(BUILT_IN_ROBOTS)}) or a "
        f"catalogue arm ({', '.join(CATALOGUE_ARMS)}: its default task; another with --task)",
        **kwargs,
    )
    add_task_option(p)


def add_task_option(p: argparse.ArgumentParser) -> None:
    """--task: a catalogue arm's task (:func:`robot_with_task`)."""
    p.add_argument(
        "--task",
        help="a catalogue arm's task: 'pose', 'xyz' or coordinates among x y z rx ry rz "
        "(default: the arm's)",
    )


class RobotFileError(Exception):
    """An entry of the robot file ``source`` refused, under its ``field`` in the file (such as
    ``task.0`` or ``limits``): no option of the command, though some share its name."""

    def __init__(self, message: str, field: str, source: str) -> None:
        super().__init__(message)
        self.field, self.source = field, source


def robot_with_task(source: str, task: str | None) -> Robot:
    """The robot of ``--robot`` (a file or a name), a catalogue arm with ``--task`` if given."""
    from ..engine.arms import ARMS
    from ..engine.exceptions import InvalidInputError
    from ..engine.robot_spec import load_robot, robot_from_dict

    if task is None:
        try:
            return load_robot(source)
        except InvalidInputError as error:
            if error.field in (None, "robot"):  # (the file as a whole: --robot's)
                raise
            raise RobotFileError(str(error), error.field, source) from None
    if source not in ARMS:
        raise InvalidInputError(
            f"--task is for a catalogue arm ({sorted(ARMS)}); a robot file holds its task", "task"
        )
    return robot_from_dict({"name": source, "task": task})


def _common(p: argparse.ArgumentParser) -> None:
    add_robot_option(p, required=True)
    p.add_argument(
        "--x0",
        help="start configuration, e.g. '0, 0, pi/2' (a leading minus: --x0=-1,0,0; default: "
        "the robot's)",
    )
    p.add_argument("--algorithm", choices=ALGORITHM_NAMES, default="pseudoinverse")
    p.add_argument("--augmentation", help="augmenting map of the extended inverse (its name)")
    add_algorithm_parameter_options(p)
    add_run_options(p)
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")


def _setup(args: argparse.Namespace) -> tuple[Robot, list[float], dict]:
    robot = robot_with_task(args.robot, args.task)
    x0 = parse_vector(args.x0, "--x0") if args.x0 is not None else list(robot.spec.default_x0)
    return robot, x0, run_settings(args, robot.spec)


def _limits(robot: Robot, report):
    """The run's limits report (``report(limits, names)``), or None for a robot without."""
    from ..engine.limits import limit_names, robot_limits

    limits = robot_limits(robot.kinematics)
    return None if limits is None else report(limits, limit_names(robot.kinematics))


def _notes(robot: Robot) -> dict:
    """``{"notes": [...]}``: what building the robot skipped (a URDF's mesh references)."""
    notes = list(getattr(robot.kinematics, "notes", ()))
    return {"notes": notes} if notes else {}


def _fmt(v) -> str:
    return "(" + ", ".join(f"{float(t):.10g}" for t in v) + ")"


def _inverse(robot, args: argparse.Namespace, x0):
    """The inverse the command line asks for (the posture's default rest: the robot's home,
    else x0)."""
    refuse_unused_options(args, [args.algorithm])
    return robot.inverse(
        args.algorithm,
        args.augmentation,
        algorithm_parameters=algorithm_parameters(args, args.algorithm),
        x0=x0,
    )


def _document(robot, result, report, as_json: bool, findings=()) -> None:
    """The result in the engine's names (``as_dict()``: x0, y_d or targets, x, legs, ...) with
    the robot, its limits' report, notes and the units of x and y (and a repeatability run's
    ``findings``, :meth:`~jik.engine.RepeatabilityResult.findings`); printed as JSON, or its
    first lines as text."""
    out = {
        "robot": robot.spec.title,
        **result.as_dict(),
        **({"findings": [{"text": f.text, "role": f.role} for f in findings]} if findings else {}),
        **({} if report is None else {"limits": report.as_dict()}),
        **_notes(robot),
        "units": robot.units.summary(),
    }
    if as_json:
        print(json.dumps(out, allow_nan=False))  # (as_dict: NaN as None)
    else:
        print(f"{out['robot']}, {out['algorithm']}: {result.message}")
        for note in out.get("notes", ()):
            print(f"  note: {note}")


def solve_command(args: argparse.Namespace) -> int:
    from ..engine.limits import solve_report
    from ..engine.solver import solve

    robot, x0, settings = _setup(args)
    target = (
        parse_vector(args.target, "--target")
        if args.target is not None
        else robot.spec.default_target
    )
    res = solve(_inverse(robot, args, x0), x0, target, record=True, **settings)
    report = _limits(robot, lambda limits, names: solve_report(limits, res, names))
    _document(robot, res, report, args.json)
    if not args.json:
        print(
            f"  x0 = {_fmt(x0)}\n  x  = {_fmt(res.x)}\n  k(x) = {_fmt(res.y)}, "
            f"|k(x) - target| = {res.error:.3g}"
        )
        if report is not None:
            print(f"  joint limits: {report}")
    return 0 if res.success else 1


def repeatability_command(args: argparse.Namespace) -> int:
    from ..engine.limits import repeatability_report, robot_limits
    from ..engine.repeatability import repeatability
    from ..engine.units import norm_unit

    robot, x0, settings = _setup(args)
    path = (
        parse_path(args.path, "--path")
        if args.path is not None
        else robot.spec.default_loop("--path")
    )
    inverse = _inverse(robot, args, x0)
    record = robot_limits(robot.kinematics) is not None  # (limits: check whole legs)
    rep = repeatability(inverse, x0, path, cycles=args.cycles, record=record, **settings)
    report = _limits(robot, lambda limits, names: repeatability_report(limits, rep, names))
    findings = rep.findings(norm_unit(robot.units.x))
    _document(robot, rep, report, args.json, findings)
    if not args.json:
        print(f"  x0 = {_fmt(x0)}; {len(rep.targets)} legs a cycle")
        for c, (end, drift) in enumerate(zip(rep.cycle_end, rep.drift, strict=True)):
            print(f"  cycle {c + 1}: x = {_fmt(end)}, |x - x0| = {drift:.3e}")
        if report is not None:
            print(f"  joint limits: {report}")
        print("\n".join(f"  {f.text}" for f in findings))
    return 0 if rep.success else 1


#: The engine's names of inputs that the command line takes under another option's name.
OPTION_OF_FIELD = {
    "y_d": "target",
    "targets": "path",
    "n_starts": "starts",
    "shifts": "shift",
    "scales": "scale",
}


def refused(command: str, error: Exception, args: argparse.Namespace | None = None) -> int:
    """Say on stderr why ``jik command`` refused its input, and the option it is about (of
    ``args``'s options; else the engine's field); the exit status 2."""
    field = getattr(error, "field", None) or ""
    head = re.split(r"[.\[]", field.lstrip("-"))[0]
    option = OPTION_OF_FIELD.get(head, head)
    if head == "backend":  # (jik atlas's --processes or --dask)
        option = "dask" if getattr(args, "dask", None) is not None else "processes"
    if head == "active_joints" and getattr(args, "task", None) is not None:
        option = "task"  # (a catalogue arm's joints against the task that --task gave it)
    if isinstance(error, RobotFileError):
        where = f" (field {field} of the robot file {error.source})"
    elif field and option in vars(args or argparse.Namespace()):
        where = f" (option --{option.replace('_', '-')})"
    else:
        where = f" (field {field})" if field else ""
    sys.stderr.write(f"jik {command}: {error}{where}\n")
    return 2


def guarded(command):
    """``command`` with the engine's refusals said in one line (:func:`refused`)."""

    def run(args: argparse.Namespace) -> int:
        from ..engine.exceptions import JikError

        try:
            return command(args)
        except (JikError, RobotFileError) as exc:
            return refused(args.command, exc, args)

    return run


def add_robot_commands(sub) -> None:
    """Register ``solve`` and ``repeatability`` on the ``jik`` command's subparsers."""
    p = sub.add_parser("solve", help="solve k(x) = target for a robot (file or built-in name)")
    _common(p)
    p.add_argument(
        "--target", help="task point, e.g. '1, 1.5' (--target=-1,1.5; default: the robot's)"
    )
    p.set_defaults(func=guarded(solve_command))

    p = sub.add_parser("repeatability", help="drive a robot around a closed task path")
    _common(p)
    p.add_argument(
        "--path",
        help="task points 'y1,y2; y1,y2; ...' (--path='-1,1; 1,1'; default: the robot's); "
        "the return leg to k(x0) closes it",
    )
    p.add_argument("--cycles", type=int, default=1, help="number of cycles (default 1)")
    p.set_defaults(func=guarded(repeatability_command))
