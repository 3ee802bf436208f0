"""The dashboard's controls, described once: the page and the 3D scene are both built from this.

:func:`controls` lists the controls of a dashboard state, generated from the engine's registry:
keys, labels, help text, kinds, ranges, steps and options; :func:`control_values` gives each
control's value as shown, and :func:`controls_message` both, for a page.

A control's ``key`` is a dotted path into the state: ``gamma``, ``x0.1`` (one coordinate of the
start x0), ``robot_parameters.l``, ``robot_parameters.q0`` (a vector parameter, edited whole),
``augmentation_parameters.a``, ``algorithm_parameters.gain`` (a parameter of a chosen
algorithm), ``algorithm_parameters.rest.1`` (one coordinate of the posture inverse's rest, shown
while it is chosen), ``algorithms`` (the chosen ones, a ``checks`` control), ``path`` (edited as
text).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass
from typing import Any

from ...engine.arms import ARMS
from ...engine.registry import ROBOTS
from ...engine.solve_rules import DISCRETE_GAMMA_BOUND, MAX_ITERATIONS, MAX_STEPS, MODES, TOL_MIN
from ..compute.schemas import MAX_ITERATIONS_CAP
from .algorithms import STYLES, joint_box, posture_rest, scalar_parameters
from .control_changes import DISCRETE_GAMMA_ON_SWITCH, lookup, path_format, path_text
from .glossary import PARAMETER_LABELS, SYMBOLS
from .robots import state_kinematics, state_spec

#: gamma's resolution: the page's log-scale slider and the scene's slider both land on it.
GAMMA_STEP = 0.001
#: gamma's slider range per mode: the decay rate of eq. (5) (continuous), the step of the
#: discrete iteration, which converges only below the engine's DISCRETE_GAMMA_BOUND.
GAMMA_RANGE = {"continuous": (0.01, 10.0), "discrete": (0.01, DISCRETE_GAMMA_BOUND - 0.01)}
#: Largest number of cycles offered by the dashboard (the engine accepts more).
MAX_DASHBOARD_CYCLES = 20
#: The least cap on a leg's steps that the page offers and the state takes (a request takes 1):
#: a digit typed on the way to "500" in the scene's box is then no run of its own, and the
#: scene's slider, which cannot show a value below its range, shows every state's.
MIN_ITERATIONS = 10
#: Positions of a slider between its ends (x0's: finer).
SLIDER_STEPS, X0_STEPS = 200, 400
#: A computation shows its progress once it has run this long [s].
PROGRESS_AFTER = 0.5
#: What the task selector offers.
TASKS = (("path", "closed path"), ("target", "single target"))
#: The groups (fieldsets of the page, folders of the scene), in order.
GROUPS = (("algorithm", "Robot and algorithm"), ("start", "Start and task"))


@dataclass(frozen=True)
class Control:
    """One control. ``kind``: ``select`` (``options``), ``slider`` (``minimum``..``maximum`` by
    ``step``, on a ``log`` scale or not, ``integer`` or not), ``vector`` (``size`` numbers, each
    within ``minimum``/``maximum`` lists), ``text`` (``format``), ``preset`` (a button that sets
    ``key`` to ``value``), ``checks`` (any of ``options``, at least one: a list);
    ``inline``: a select shown as buttons."""

    key: str
    label: str
    kind: str
    help: str = ""
    options: tuple[tuple[Any, str], ...] = ()  # (value: text, or a number, label)
    group: str = "algorithm"
    minimum: Any = None
    maximum: Any = None
    step: float | None = None
    log: bool = False
    integer: bool = False
    size: int = 0
    format: str = ""
    value: Any = None
    id: str = ""
    #: A select whose options all show at once (buttons on the page: one click to any).
    inline: bool = False

    def as_dict(self) -> dict:
        out = asdict(self)
        out["id"] = self.id or element_id(self.key)
        out["options"] = [list(o) for o in self.options]
        return {k: v for k, v in out.items() if v not in (None, "", (), [], 0, False)}


#: A user map's formula is shown on its button up to this many characters.
MAP_LABEL_CHARS = 48


def _map_label(aug) -> str:
    """A map's button: its name and equation, or for a user's formula map its formula h (a
    robot's default map is one: "formula: h = x3")."""
    text = aug.description
    if not text.startswith("h = "):
        return f"{aug.name} {aug.equation}"
    short = text if len(text) <= MAP_LABEL_CHARS else text[: MAP_LABEL_CHARS - 1] + "…"
    return f"{aug.name}: {short}"


def controls(state) -> list[Control]:
    """Every control of ``state`` (a :class:`~jik.app.dashboard.DashboardState`), in order."""
    spec = state_spec(state)
    aug = spec.augmentation(state.augmentation)
    lo, hi = GAMMA_RANGE[state.mode]
    robots = [(name, ROBOTS[name].title) for name in ROBOTS]
    robots += [(name, f"{arm.title} (arm)") for name, arm in ARMS.items()]
    if state.robot not in (*ROBOTS, *ARMS):
        robots.append((state.robot, f"your robot: {spec.title}"))
    out = [
        Control("robot", "robot", "select", "the robot (section 6 of the paper)", tuple(robots)),
        Control(
            "mode",
            "mode",
            "select",
            "continuous: the ODE (7); discrete: the iteration x <- x - gamma J# e (switching "
            f"to it takes a gamma above {DISCRETE_GAMMA_ON_SWITCH:g}, the full Newton step, down "
            "to it)",
            tuple((m, m) for m in MODES),
        ),
        Control(
            "gamma",
            "γ (decay rate)",
            "slider",
            SYMBOLS["gamma"],
            minimum=lo,
            maximum=hi,
            step=GAMMA_STEP,
            log=True,
        ),
        iterations_control(state),
        tolerance_control(state),
    ]
    out += _sliders("robot_parameters", spec.parameters)
    for v in spec.vector_parameters:
        out.append(
            Control(
                f"robot_parameters.{v.name}",
                v.name,
                "vector",
                explained(v.name, v.description),
                minimum=list(v.minimum),
                maximum=list(v.maximum),
                step=0.1,
                size=len(v.default),
            )
        )
        for name, preset in v.presets.items():
            text = f"set {v.name} to the paper's pose {name}"
            out.append(preset_button(f"robot_parameters.{v.name}", name, preset, text, True))
    out.append(
        Control(
            "augmentation",
            "augmenting map h",
            "select",
            SYMBOLS["h"] + "; one button per map of the paper for this robot",
            tuple((a.name, _map_label(a)) for a in spec.augmentations),
            inline=True,
        )
    )
    out += _sliders("augmentation_parameters", aug.parameters)
    out.append(
        Control(
            "algorithms",
            "algorithms",
            "checks",
            "the inverses J# run side by side, one colour each (at least one)",
            tuple((a, s.label) for a, s in STYLES.items()),
            inline=True,
        )
    )
    out += _sliders("algorithm_parameters", scalar_parameters(state.algorithms))
    if "posture" in state.algorithms:
        out += rest_controls(state, spec)
    text = "start configuration, coordinate {}. " + SYMBOLS["x0"]
    out += joint_sliders("x0", "start", spec, text, joint_box(spec, state_kinematics(state)))
    if len(spec.variable_names) > 3:
        names = spec.variable_names
        out.append(
            Control(
                "cspace_axes",
                "configuration-space axes",
                "select",
                "the three coordinates the configuration-space panel shows",
                tuple(
                    ("".join(f"{k:x}" for k in c), ", ".join(names[k] for k in c))
                    for c in itertools.combinations(range(len(names)), 3)
                ),
                group="start",
            )
        )
    if spec.default_path:
        text = "drive a closed path cycle after cycle, or solve for one target"
        out.append(Control("task", "task", "select", text, TASKS, group="start"))
    if state.task == "path":
        written = path_format(len(state.target))
        out.append(
            Control(
                "path",
                "closed path",
                "text",
                f"task points visited in order, a point per line ({written}); the path closes "
                "back to k(x0)",
                format=written,
                group="start",
            )
        )
        out.append(
            Control(
                "cycles",
                "cycles",
                "slider",
                "times around the path",
                minimum=1,
                maximum=MAX_DASHBOARD_CYCLES,
                step=1,
                integer=True,
                group="start",
            )
        )
    else:
        text = f"target task point ({', '.join(spec.task_names)})"
        size = len(spec.task_names)
        out.append(Control("target", "target", "vector", text, step=0.1, size=size, group="start"))
    return out


def rest_controls(state, spec) -> list[Control]:
    """The posture inverse's rest x_rest: a slider per joint variable over what it accepts
    (:func:`~jik.app.dashboard.algorithms.joint_box`), and buttons setting it to the start x0
    and, for a robot with one, to its home (the default)."""
    kin, key = state_kinematics(state), "algorithm_parameters.rest"
    home = getattr(kin, "home", None)
    default = "the robot's home" if home is not None else "the start x0"
    text = f"rest configuration, coordinate {{}} (default: {default}; moving one sets the "
    text += f"rest, the others at their nearest value a slider takes). {SYMBOLS['rest']}"
    out = joint_sliders(key, "algorithm", spec, text, joint_box(spec, kin))
    out.append(preset_button(key, "x0", "x0", "set the rest to the start configuration x0"))
    if home is not None:
        shown = ", ".join(f"{t:.3g}" for t in home)
        out.append(preset_button(key, "home", home, f"set the rest to the robot's home ({shown})"))
    return out


def preset_button(key: str, name: str, value, text: str, numbers: bool = False) -> Control:
    """A button setting the control ``key`` (``robot_parameters.q0``) to ``value``, labelled
    ``q0 = A`` (with the numbers if ``numbers``)."""
    short = key.rpartition(".")[2]
    shown = f" ({', '.join(f'{t:.2f}' for t in value)})" if numbers else ""
    value = value if isinstance(value, str) else [float(t) for t in value]
    label, button = f"{short} = {name}{shown}", f"ctl-preset-{short}-{name}"
    return Control(key, label, "preset", text, value=value, id=button)


def joint_sliders(key: str, group: str, spec, text: str, box) -> list[Control]:
    """A slider per joint variable over its range in ``box``, keyed ``key.<i>`` and labelled
    ``x0: x1``, ``rest: x1``; ``text``: the help, with ``{}`` for the variable's name."""
    short = key.rpartition(".")[2]
    return [
        Control(
            f"{key}.{i}",
            f"{short}: {name}",
            "slider",
            text.format(name),
            group=group,
            minimum=lo,
            maximum=hi,
            step=(hi - lo) / X0_STEPS,
        )
        for i, (name, (lo, hi)) in enumerate(zip(spec.variable_names, box, strict=True))
    ]


def explained(name: str, description: str) -> str:
    """A parameter's description from the registry, with the paper's symbol explained."""
    return f"{description}. {SYMBOLS[name]}" if name in SYMBOLS else description


def iterations_control(state) -> Control:
    """The cap on each leg's iterations (discrete mode) or integrator steps (continuous), which
    a leg that does not converge names in its message."""
    what = "iterations" if state.mode == "discrete" else "integrator steps"
    return Control(
        "max_iterations",
        f"max {what} per leg",
        "slider",
        f"a leg that has not reached its target after this many {what} stops and "
        "says so (raise it for far targets or small γ; the work grows with it)",
        minimum=MIN_ITERATIONS,
        maximum=MAX_ITERATIONS_CAP,
        step=1,
        log=True,
        integer=True,
    )


def tolerance_control(state) -> Control:
    """The tolerance of every leg, a power of ten from 1e-4 down to the engine's
    :data:`~jik.engine.solve_rules.TOL_MIN`, and the state's own when it is another (a link
    or the session API may set any the model takes)."""
    decades = {float(f"1e-{k}"): f"1e-{k}" for k in range(4, 1 - int(math.log10(TOL_MIN)))}
    shown = {**decades, float(state.tolerance): f"{state.tolerance:.6g}", **decades}
    return Control(
        "tolerance",
        "tolerance",
        "select",
        "a leg stops once its task error ||k(x) − y_d|| is below this; lower asks for more "
        "digits, and more steps",
        tuple(sorted(shown.items(), reverse=True)),
    )


def max_iterations(state) -> int:
    """The cap in force: the state's, or the engine's default for its mode."""
    if state.max_iterations is not None:
        return int(state.max_iterations)
    return MAX_ITERATIONS if state.mode == "discrete" else MAX_STEPS


def element_id(key: str) -> str:
    """The page's element id of the control ``key``: ``ctl-gamma``, ``ctl-x0-1``, ``ctl-l``
    (a robot parameter), ``ctl-aug-a`` (a parameter of the map)."""
    short = (
        key.replace("robot_parameters.", "")
        .replace("augmentation_parameters.", "aug-")
        .replace("algorithm_parameters.", "alg-")
    )
    return "ctl-" + short.replace(".", "-")


def about(key: str, field: str) -> bool:
    """Whether the control ``key`` is about ``field`` (a refusal's dotted path): the field, a
    coordinate of it (``x0.1`` of ``x0``) or its vector. The page gets the keys it marks from
    :func:`controls_about`."""
    return key == field or field.startswith(f"{key}.") or key.startswith(f"{field}.")


def controls_about(spec: list[Control], field: str | None) -> list[str]:
    """The keys of the controls of ``spec`` about ``field`` (:func:`about`), in the panel's
    order: where the page shows a refusal of ``field`` or a run that stopped there (none for
    None)."""
    return [c.key for c in spec if field and about(c.key, field)]


def control_values(state, spec: list[Control] | None = None) -> dict[str, Any]:
    """Each control's value as shown (the path as text), by key; ``spec``: the state's
    :func:`controls` when the caller has them."""
    d = state.as_dict()
    values: dict[str, Any] = {}
    rest: list[float] = []
    for c in controls(state) if spec is None else spec:
        if c.kind == "preset":
            continue
        if c.key.startswith("algorithm_parameters.rest."):
            rest = rest or posture_rest(state, state_kinematics(state))[0]
            values[c.key] = rest[int(c.key.rpartition(".")[2])]
        elif c.key == "max_iterations":
            values[c.key] = max_iterations(state)
        elif c.key == "cspace_axes":
            values[c.key] = state.cspace_axes or "012"
        else:
            values[c.key] = path_text(state.path) if c.key == "path" else lookup(d, c.key)
    return values


def controls_message(state, field: str | None = None) -> dict[str, Any]:
    """What a page needs to show the controls of ``state``: the controls, grouped, and their
    values; with a refused ``field``, the keys of the controls it is about ("about")."""
    spec = controls(state)
    message = {
        "groups": [list(g) for g in GROUPS],
        "controls": [c.as_dict() for c in spec],
        "values": control_values(state, spec),
    }
    return message | ({"about": controls_about(spec, field)} if field else {})


def _sliders(head: str, parameters) -> list[Control]:
    """A slider per scalar parameter (:class:`~jik.engine.parameters.Parameter`: its name,
    description and range), keyed ``head.name``."""
    return [
        Control(
            f"{head}.{p.name}",
            PARAMETER_LABELS.get(p.name, p.name),
            "slider",
            explained(p.name, p.description),
            minimum=p.minimum,
            maximum=p.maximum,
            step=(p.maximum - p.minimum) / SLIDER_STEPS,
        )
        for p in parameters
    ]
