"""The scene's GUI controls, built from the dashboard's control specification
(:func:`jik.app.dashboard.controls.controls`, from which the page builds its own): the same
controls, labels, ranges and values. A change is sent by its control key, as the page sends it
(a text box's by its "apply" button, as the page's by Enter); the inputs a refused change was
about are marked until a change is accepted, and those where the runs on screen stopped (a
singular start) until the next result, as the page marks its boxes."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from functools import partial
from typing import Any

import viser

from ..dashboard.control_changes import DECIMALS, path_text
from ..dashboard.controls import GROUPS, Control, about, control_values, controls

#: Before the label of an input the dashboard refused a value of, or where a run stopped (its
#: hint says which and why).
MARK = "⚠ "


class Syncing(threading.local):
    """Whether this thread is setting a GUI's inputs to the values in force (``with syncing:``
    while it does, ``if syncing:`` in the inputs' callbacks): the callbacks viser calls from
    within an assignment are then not a user's change. Per thread: a user's change, which
    viser's thread delivers, is never dropped while another thread syncs."""

    depth = 0  # (nested syncs of this thread)

    def __bool__(self) -> bool:
        return self.depth > 0

    def __enter__(self) -> None:
        self.depth += 1

    def __exit__(self, *_) -> None:
        self.depth -= 1


class SceneControls:
    """The inputs of one scene's GUI, one folder per group of the specification; a change is
    ``send(patch)``, keyed by control keys (``{"x0.1": 0.4}``)."""

    def __init__(self, gui: viser.GuiApi, send: Callable[[dict], None]) -> None:
        self._gui = gui
        self._send = send
        self.inputs: dict[str, Any] = {}  # control key -> viser input handle
        self.folders: list = []
        # control key -> its value as its input takes it (a select's label, a vector's tuple)
        self._shown: dict[str, Callable[[Any], Any]] = {}
        # control key -> its viser elements (a checks control's boxes) with their label and hint
        self._plain: dict[str, list[tuple[Any, str, str]]] = {}
        # "refused" / "stopped" -> control key -> the message its input's hint says
        self._notes: dict[str, dict[str, str]] = {"refused": {}, "stopped": {}}
        self._marked: set[str] = set()  # the keys of the inputs marked
        self.applies: dict[str, Any] = {}  # control key -> the button that sends its text
        self._shape: list[dict] | None = None  # the specification on screen
        self.syncing = Syncing()
        self._lock = threading.RLock()

    def show(self, state) -> None:
        """Show ``state``, a change accepted: the inputs are built anew when its controls differ
        from those on screen (another robot, map, mode or task), else set to its values; a
        refusal's marks go."""
        spec = controls(state)
        shape = [c.as_dict() for c in spec]
        with self._lock:
            if shape != self._shape:
                # (new inputs, unmarked: the old ones get no update, which viser's client would
                # apply after their removal in the same batch)
                self._shape = shape
                self._build(spec, control_values(state, spec))
            else:
                self.mark("refused", ())
                self.sync(state)

    def sync(self, state) -> None:
        """Set every input to the value in force (a user's own change included)."""
        values = control_values(state)
        with self.syncing:
            for key, handle in self.inputs.items():
                shown = self._shown.get(key)
                try:
                    handle.value = values.get(key) if shown is None else shown(values.get(key))
                except (ValueError, AssertionError):
                    pass

    def mark(self, kind: str, fields: Iterable[tuple[str | None, str]]) -> None:
        """Mark the inputs about each ``(field, message)`` of ``fields`` (:func:`about`), as
        ``kind``: ``"refused"``, a refused change's field (until a change is accepted or another
        is refused), or ``"stopped"``, where a run of the result on screen stopped (until the
        next result). A marked input has :data:`MARK` before its label and "<kind>: <message>"
        as its hint."""
        with self._lock:
            notes: dict[str, list[str]] = {}
            for field, message in fields:
                for key in self.inputs:
                    if field and about(key, field) and message not in notes.get(key, []):
                        notes.setdefault(key, []).append(message)
            self._notes[kind] = {key: "; ".join(said) for key, said in notes.items()}
            hints: dict[str, list[str]] = {}
            for k, kind_notes in self._notes.items():
                for key, message in kind_notes.items():
                    hints.setdefault(key, []).append(f"{k}: {message}")
            for key in self._marked | set(hints):
                for element, label, hint in self._plain.get(key, ()):
                    element.label = MARK + label if key in hints else label
                    element.hint = "; ".join(hints[key]) if key in hints else hint
            self._marked = set(hints)

    def _build(self, spec: list[Control], values: dict[str, Any]) -> None:
        for folder in self.folders:
            folder.remove()
        self.folders, self.inputs, self._shown, self._plain = [], {}, {}, {}
        self.applies = {}
        self._notes, self._marked = {"refused": {}, "stopped": {}}, set()
        with self.syncing:
            for order, (group, title) in enumerate(GROUPS, start=2):
                with self._gui.add_folder(title, order=order) as folder:
                    self.folders.append(folder)
                    for control in spec:
                        if control.group == group:
                            self._add(control, values.get(control.key))

    def _change(self, patch: dict) -> None:
        if not self.syncing:
            self._send(patch)

    def _add(self, control: Control, value: Any) -> None:
        """One viser input for ``control``: what it shows of a value (``self._shown``) and
        what it sends of its own (``sent``)."""
        gui, key = self._gui, control.key
        handle: Any
        sent: Callable[[Any], Any]  # (None: nothing to send)
        if control.kind == "preset":
            button = gui.add_button(control.label, hint=control.help)
            button.on_click(lambda _: self._change({key: control.value}))
            return
        if control.kind == "checks":
            checks = self.inputs[key] = Checks(
                gui, control, value, lambda v: self._change({key: v})
            )
            self._plain[key] = [(box, box.label, control.help) for box in checks.boxes.values()]
            return
        if control.kind == "select":
            sent = {label: v for v, label in control.options}.__getitem__
            labels = {v: label for v, label in control.options}
            self._shown[key] = lambda v: labels.get(v, v)
            handle = gui.add_dropdown(
                control.label, list(labels.values()), initial_value=labels[value], hint=control.help
            )
        elif control.kind == "slider":
            sent = partial(slider_value, control)
            handle = gui.add_slider(
                control.label,
                min=control.minimum,
                max=control.maximum,
                step=control.step,
                initial_value=min(max(value, control.minimum), control.maximum),
                hint=control.help,
            )
        elif control.kind == "vector" and control.size in (2, 3):
            add: Any = gui.add_vector2 if control.size == 2 else gui.add_vector3
            lo = None if control.minimum is None else tuple(control.minimum)
            hi = None if control.maximum is None else tuple(control.maximum)
            sent, self._shown[key] = list, tuple
            handle = add(
                control.label, tuple(value), min=lo, max=hi, step=control.step, hint=control.help
            )
            # (viser's boxes show, and take as typed, only the decimals of the step and the
            # first value: else Manipulator 2's target (0, 2) by 0.1 took 0.25 as 0.2)
            handle.precision = max(handle.precision, DECIMALS)
        else:  # text (the path, a point per line), or a vector of another size: as text, parsed
            # by the server, sent by its button: viser's box sends every keystroke, and a
            # half-typed path would be refused and reset while the user types
            self._shown[key] = as_text
            multiline = control.kind == "text"
            text = gui.add_text(
                control.label, as_text(value), hint=control.help, multiline=multiline
            )
            self.applies[key] = gui.add_button(
                f"apply {control.label}", hint=f"send the {control.label} typed above"
            )
            self.applies[key].on_click(lambda _: self._change({key: text.value}))
            self.inputs[key] = text
            self._plain[key] = [(text, control.label, control.help)]
            return

        def update(event) -> None:
            value = sent(event.target.value)
            if value is not None:
                self._change({key: value})

        handle.on_update(update)
        self.inputs[key] = handle
        self._plain[key] = [(handle, control.label, control.help)]


def slider_value(control: Control, value: float) -> float | int | None:
    """What a slider of ``control`` sends of its ``value``: an integer for an integer control
    (viser's slider gives a float), and None for a value off its range, a number being typed in
    the slider's box, which viser sends at every keystroke ("5" on the way to "500"; a refusal
    would reset the box under the typing): the box brings it into the range when it loses focus,
    and sends that."""
    if not control.minimum <= value <= control.maximum:
        return None
    return round(value) if control.integer else float(value)


def as_text(value) -> str:
    """A text input's value: the path's text, or a vector's numbers as the path writes a point
    (:func:`~jik.app.dashboard.control_changes.path_text`: as a user types it)."""
    return value if isinstance(value, str) else path_text([value])


class Checks:
    """A ``checks`` control (any of its options) as one viser checkbox per option; ``value``
    is the list of those checked, in the options' order."""

    def __init__(self, gui, control: Control, value, send: Callable[[list], None]) -> None:
        self.label = control.label
        self.boxes = {
            v: gui.add_checkbox(label, v in value, hint=control.help)
            for v, label in control.options
        }
        for box in self.boxes.values():
            box.on_update(lambda _: send(self.value))

    @property
    def value(self) -> list:
        return [v for v, box in self.boxes.items() if box.value]

    @value.setter
    def value(self, chosen) -> None:
        for v, box in self.boxes.items():
            box.value = v in chosen
