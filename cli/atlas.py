"""``jik atlas``: a repeatability atlas from the command line (:mod:`jik.engine.atlas`).

    jik atlas --robot manipulator2 --path "0,1; 1,1; 1,2; 0,2" --starts 4096 --cycles 3 \\
        --algorithm pseudoinverse --algorithm extended [--processes 2 | --dask local:2] \\
        --out atlas.json

The path (default: the robot's closed path) is a loop from its first point: the starts lie on
that point's self-motion curve, at arc lengths s on a grid (or sampled), s = 0 where eq. (7)
from the robot's default start (or ``--reference``) reaches the point; the arc is where the
curve stays in the robot's configuration box, or ``--arc``. Writes ``--out`` (JSON: the
inputs, the starts, and per algorithm the drift after each cycle, success and leg ends), a CSV
beside it for large atlases (or with ``--csv``), and an HTML figure of the drift map when
plotly is installed. The CSV is the engine's atlas table (``AtlasResult.columns``), written
chunk by chunk: a row per run, algorithm, cycle and leg (per cycle with ``--no-leg-ends``),
columns ``algorithm, path, start, s, cycle, leg, drift, success, x0_1..x0_p, x_1..x_p`` (x0 the
start, x the leg's end; with ``--shift`` or ``--scale``, each path's ``scale`` and
``shift_1..shift_r`` after ``path``); the JSON's ``variable_names`` name the coordinates k.
``--robot`` is a built-in robot's name (``--param`` sets its parameters), a catalogue arm's
(``panda``, with its default task) or a user's robot file
(:func:`jik.engine.robot_spec.load_robot`, as for ``jik solve``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

from ..engine.exports import json_values, plural
from .algorithm_options import (
    ALGORITHM_NAMES,
    add_algorithm_parameter_options,
    add_run_options,
    algorithm_parameters,
    refuse_unused_options,
    run_settings,
)
from .atlas_output import CsvWriter, Gathered, write_figure
from .robot_commands import (
    RobotFileError,
    add_robot_option,
    point_texts,
    refused,
    robot_with_task,
)

#: Atlases of more runs than this write their arrays to the CSV only (the JSON keeps a summary).
JSON_RUNS = 20000
#: Points per line of the figure (every k-th start beyond this).
FIGURE_POINTS = 20000


def add_atlas_parser(sub) -> None:
    """Register ``jik atlas`` on the subcommands ``sub`` of the ``jik`` parser."""
    p = sub.add_parser(
        "atlas",
        help="repeatability atlas: drift after each cycle over many starts (and paths)",
        description=__doc__.split("\n\n")[2],
    )
    add_robot_option(p, default="manipulator2")
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a robot parameter (repeat it), e.g. l=1.5",
    )
    p.add_argument(
        "--path", help='task points "y1,y2; y1,y2; ...", a loop (default: the robot\'s closed path)'
    )
    p.add_argument("--starts", type=int, default=256, help="starts per path (default 256)")
    p.add_argument(
        "--sampling",
        choices=("grid", "sample"),
        default="grid",
        help="the starts' arc lengths on an even grid, or drawn at random (default grid)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of --sampling sample (default 0)")
    p.add_argument(
        "--arc", help='"lo,hi" (--arc=-1,2): arc lengths of the starts (default: the box)'
    )
    p.add_argument("--reference", help='"x1,x2,...": where s = 0 comes from (robot default)')
    p.add_argument("--cycles", type=int, default=3, help="cycles of each run (default 3)")
    p.add_argument(
        "--algorithm",
        action="append",
        choices=ALGORITHM_NAMES,
        help="repeat for several, compared over the same starts (default pseudoinverse)",
    )
    add_algorithm_parameter_options(p)
    add_run_options(p)
    p.add_argument("--augmentation", help="augmenting map of the extended inverse")
    p.add_argument(
        "--shift",
        action="append",
        default=[],
        metavar='"dy1,dy2"',
        help="a translation of the path (repeat it; default none)",
    )
    p.add_argument(
        "--scale",
        action="append",
        type=float,
        default=[],
        help="a scale of the path about its first point (default 1)",
    )
    p.add_argument(
        "--chunk",
        type=int,
        default=None,
        help="starts per chunk (default: at most 2048, and 16 chunks or more from 256 runs)",
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument("--processes", type=int, help="run chunks in N local processes")
    where.add_argument("--dask", metavar="ADDRESS", help="a Dask scheduler, or local:N")
    p.add_argument("--out", default="atlas.json", help="output JSON (default atlas.json)")
    p.add_argument("--csv", action="store_true", help="also write the CSV for a small atlas")
    p.add_argument("--no-figure", action="store_true", help="write no HTML figure")
    p.add_argument(
        "--no-leg-ends",
        action="store_true",
        help="leave the leg ends out (the CSV: a row per cycle, no x_k; far smaller)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=atlas_command)


def _numbers(text: str, what: str) -> list[float]:
    from ..engine.exceptions import InvalidInputError

    try:
        return [float(t) for t in text.split(",")]
    except ValueError:
        raise InvalidInputError(
            f"{what} must be comma-separated numbers, got {text!r}", _field(what)
        ) from None


def _field(option: str) -> str:
    """The field an option's refusal names: ``param`` of ``--param l``."""
    return option.lstrip("-").split()[0]


def _points(text: str, what: str) -> list[list[float]]:
    """``"1,1; 1,2"`` -> [[1, 1], [1, 2]]; a trailing ``;`` ends the list."""
    return [_numbers(t, what) for t in point_texts(text)]


def backend_option(args: argparse.Namespace) -> str:
    if args.processes is not None:
        return f"processes:{args.processes}"
    if args.dask is not None:
        return f"dask:{args.dask}"
    return "inprocess"


class Progress:
    """A progress bar on stderr (rewritten in place on a terminal, a line each in a log): runs
    done over every algorithm, elapsed time and the time left."""

    def __init__(self, quiet: bool, algorithms: int = 1) -> None:
        self.quiet = quiet
        self.algorithms = algorithms
        self.t0 = time.perf_counter()
        self.open = False  # (a bar is on stderr's last line, not ended by a newline)

    def __call__(self, done: int, total: int) -> None:
        """``done`` of ``total`` starts (times paths), each run by every algorithm."""
        if self.quiet:
            return
        t = time.perf_counter() - self.t0
        left = f"{t * (total - done) / done:.0f}" if done else "?"
        bar = "#" * int(30 * done / total)
        A = self.algorithms
        text = (
            f"  atlas [{bar:<30}] {A * done}/{A * total} runs ({total} starts x {A} "
            f"algorithm{'' if A == 1 else 's'}), {t:.1f} s, {left} s left "
        )
        if not sys.stderr.isatty():  # (a log: a line each)
            sys.stderr.write(text.rstrip() + "\n")
        else:
            sys.stderr.write("\r" + text)
            self.open = True
            if done >= total:
                self.end()
        sys.stderr.flush()

    def end(self) -> None:
        """End the bar's line (a message after it starts on a line of its own)."""
        if self.open:
            sys.stderr.write("\n")
            self.open = False


def atlas_command(args: argparse.Namespace) -> int:
    from ..engine.exceptions import InvalidInputError

    try:
        return _run(args)
    except (InvalidInputError, RobotFileError) as error:
        return refused("atlas", error, args)
    except OSError as error:  # (a Dask scheduler out of reach, an output that cannot be written)
        sys.stderr.write(f"jik atlas: {error}\n")
        return 2


def _run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..engine.arms import ARMS
    from ..engine.atlas import plan_atlas
    from ..engine.atlas_backends import backend_for
    from ..engine.atlas_run import iter_atlas
    from ..engine.exceptions import InvalidInputError
    from ..engine.registry import make_inverse, robot_spec
    from ..engine.self_motion import MAX_ARC

    out = _writable(Path(args.out))
    algorithms = args.algorithm or ["pseudoinverse"]
    refuse_unused_options(args, algorithms)
    # a user's robot or a catalogue arm (--task given: it must be one)
    if args.task is not None or Path(args.robot).is_file() or args.robot in ARMS:
        robot = robot_with_task(args.robot, args.task)
        if args.param:
            raise InvalidInputError(
                "--param is for a built-in robot; a robot file holds its parameters", "param"
            )
        spec, kin = robot.spec, robot.kinematics
        inverses = [
            robot.inverse(
                a,
                args.augmentation if a == "extended" else None,
                algorithm_parameters=algorithm_parameters(args, a),
            )
            for a in algorithms
        ]
    else:
        spec = robot_spec(args.robot)
        kin = spec.build(**dict(_param(t) for t in args.param))
        inverses = [
            make_inverse(
                kin,
                a,
                args.augmentation if a == "extended" else None,
                None,
                spec.name,
                algorithm_parameters=algorithm_parameters(args, a),
            )
            for a in algorithms
        ]
    path = _points(args.path, "--path") if args.path is not None else spec.default_loop("--path")
    arc = _numbers(args.arc, "--arc") if args.arc is not None else [-MAX_ARC, MAX_ARC]
    reference = (
        _numbers(args.reference, "--reference") if args.reference is not None else spec.default_x0
    )
    backend = backend_option(args)
    backend_for(backend)  # (a bad option fails here, before the curves are traced)
    plan = plan_atlas(
        inverses,
        path,
        cycles=args.cycles,
        n_starts=args.starts,
        arc=arc,
        sampling=args.sampling,
        seed=args.seed,
        reference=reference,
        box=None if args.arc or not spec.x_range else spec.x_range,
        shifts=[_numbers(s, "--shift") for s in args.shift] or None,
        scales=args.scale or None,
        chunk=args.chunk,
        **run_settings(args, spec),
    )
    big = plan.size > JSON_RUNS
    csv_path = out.with_suffix(".csv") if big or args.csv else None
    A, P, N, C = len(inverses), len(plan.paths), plan.n_starts, plan.cycles
    keep = not big  # (a small atlas is gathered for the JSON; a large one streams to the CSV)
    every = max(1, plan.size // FIGURE_POINTS)
    arrays = Gathered(plan, keep, every, legs=not args.no_leg_ends)
    progress = Progress(args.quiet, A)
    t0 = time.perf_counter()
    progress(0, plan.size)  # (the size at once: the first chunk may take minutes)
    try:
        with CsvWriter(csv_path, plan, legs=not args.no_leg_ends) as rows:
            for task, chunk in iter_atlas(plan, backend):
                arrays.add(task, chunk)
                rows.add(task, chunk)
                progress(arrays.done, plan.size)
    finally:
        progress.end()
    elapsed = time.perf_counter() - t0
    inputs = {
        "robot": spec.name,
        "robot_file": args.robot if Path(args.robot).is_file() else None,
        "task": list(spec.task_names),
        "robot_parameters": kin.parameters,
        "path": path,
        "cycles": C,
        "algorithms": list(plan.algorithms),
        "augmentation": args.augmentation,
        "algorithm_parameters": {a: algorithm_parameters(args, a) for a in algorithms},
        "starts": N,
        "sampling": args.sampling,
        "seed": args.seed,
        "arc": arc if args.arc is not None else None,
        "reference": list(reference),
        "shifts": [_numbers(t, "--shift") for t in args.shift],
        "scales": args.scale or [1.0],
        "chunk": plan.chunk,
        "gamma": plan.settings["gamma"],
        "mode": plan.settings["mode"],
        "tol": plan.settings["tol"],
        "max_iterations": plan.settings["max_iterations"],
        "backend": backend,
    }
    doc: dict[str, Any] = {
        "inputs": inputs,
        "arc": list(plan.manifolds[0].arc),
        "period": plan.manifolds[0].period,
        "paths": plan.paths.tolist(),
        "legs_per_cycle": plan.legs,
        "variable_names": list(kin.variable_names or (f"x{k + 1}" for k in range(kin.p))),
        "elapsed_s": elapsed,
        "csv": None if csv_path is None else csv_path.name,
        "summary": arrays.summary(),
    }
    if keep:
        squeeze = (lambda a: a[0]) if P == 1 else (lambda a: a)
        doc["parameter"] = json_values(plan.parameter(np.arange(N)))
        doc["starts"] = json_values(squeeze(arrays.starts))
        doc["results"] = {
            alg: {
                "drift": json_values(squeeze(arrays.drift[a])),
                "success": squeeze(arrays.success[a]).tolist(),
                "leg_ends": None if arrays.legs is None else json_values(squeeze(arrays.legs[a])),
                "failures": {
                    str(run): why for (b, run), why in sorted(arrays.failures.items()) if b == a
                },
            }
            for a, alg in enumerate(plan.algorithms)
        }
    figure = None if args.no_figure else write_figure(arrays, plan, out.with_suffix(".html"))
    doc["figure"] = None if figure is None else figure.name
    out.write_text(json.dumps(doc), encoding="utf-8")
    written = ", ".join(str(f) for f in (out, csv_path, figure) if f)
    sys.stderr.write(
        f"jik atlas: {plural(A, 'algorithm')} x {plural(plan.size, 'start')} x "
        f"{plural(C, 'cycle')} in {elapsed:.1f} s: {written}\n"
    )
    if plan.manifolds[0].period is not None:
        sys.stderr.write(
            "jik atlas: the self-motion curve closes on itself: the starts cover one turn, of "
            f"arc length {plan.manifolds[0].period:.6g}\n"
        )
    if arrays.outside is not None:  # (a robot with joint limits)
        counts = ", ".join(
            f"{alg} {int(arrays.outside[a])}" for a, alg in enumerate(plan.algorithms)
        )
        sys.stderr.write(
            f"jik atlas: runs whose start or a leg end is outside the joint limits, of "
            f"{plan.size} each: {counts}\n"
        )
    return 0


def _writable(out: Path) -> Path:
    """``out``, once its folder is known to take the files (the JSON, and the CSV and figure
    beside it): checked before anything is computed."""
    from ..engine.exceptions import InvalidInputError

    folder = out.parent
    if out.is_dir():
        raise InvalidInputError(
            f"--out {out} is a folder; give a file name, e.g. {out / 'atlas.json'}", "out"
        )
    if not folder.is_dir():
        raise InvalidInputError(f"--out {out}: there is no folder {folder}", "out")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InvalidInputError(f"--out {out}: the folder {folder} is not writable", "out")
    return out


def _param(text: str) -> tuple[str, float]:
    from ..engine.exceptions import InvalidInputError

    name, eq, value = text.partition("=")
    if not eq:
        raise InvalidInputError(f"--param must be NAME=VALUE, got {text!r}", "param")
    return name.strip(), _numbers(value, f"--param {name}")[0]
