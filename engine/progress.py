"""How a long engine computation reports its progress and hears that it is no longer wanted.

One small object, a :class:`Progress`, goes into every long computation of the engine
(:func:`jik.engine.repeatability.repeatability`, :func:`jik.engine.atlas_run.run_atlas`,
:meth:`jik.engine.characteristics.CharacteristicsMap.evaluate_batches`): the engine calls its
methods between two pieces of work, and a caller implements only what it shows.

>>> class Printer(Progress):
...     def leg(self, leg):
...         print(f"cycle {leg.cycle + 1}, leg {leg.index + 1}")
>>> # repeatability(inverse, x0, path, cycles=3, progress=Printer())

:class:`ProgressCallbacks` makes one from plain functions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .exceptions import InvalidInputError, JikError, RunCancelled
from .validation import flag

if TYPE_CHECKING:
    from .repeatability import Leg


class Progress:
    """What the engine tells a caller during a long computation, and asks it.

    Subclass it and override what you need: each method does nothing by default, and
    ``stop_at_error`` is False. :class:`ProgressCallbacks` makes one from plain functions. What
    a method raises propagates and stops the computation.

    Methods and attribute
    ---------------------
    leg(leg)
        A leg of a repeatability run ended (:class:`jik.engine.repeatability.Leg`).
    advance(done, total)
        ``done / total`` of the current piece of work is done: 0 to 1, never decreasing. Where
        the work comes in equal units they are counted: an atlas's runs
        (``run_atlas``: ``(runs_done, plan.size)``), a characteristics map's batches. Elsewhere
        ``total`` is 1.0 and ``done`` the fraction: an E2 synthesis (its stages weighted by
        their estimated cost) and a discrete repeatability leg (its way to the tolerance, on a
        log scale of the task error, eq. (5)).
    cancelled() -> bool
        Polled between two pieces of work: True stops the computation there with
        :class:`jik.engine.exceptions.RunCancelled`.
    stop_at_error : bool
        A leg of a repeatability run from one start raised a typed error (a map undefined where
        the leg starts, an algorithmic singularity of (11) there): True ends the run there with
        what it has, that leg failed with ``Leg.stopped_by`` the error; False (the default) lets
        the error propagate.
    """

    stop_at_error: bool = False

    def leg(self, leg: Leg) -> None:
        """A leg of a repeatability run ended (:class:`jik.engine.repeatability.Leg`)."""

    def advance(self, done: float, total: float) -> None:
        """``done / total`` of the current piece of work is done (see the class)."""

    def cancelled(self) -> bool:
        """Polled between two pieces of work: True stops the computation with RunCancelled."""
        return False


@dataclass(frozen=True)
class ProgressCallbacks(Progress):
    """A :class:`Progress` made of plain functions, each optional.

    Parameters
    ----------
    on_leg : callable, optional
        ``on_leg(leg)``, called as :meth:`Progress.leg`.
    on_advance : callable, optional
        ``on_advance(done, total)``, called as :meth:`Progress.advance`.
    is_cancelled : callable, optional
        ``is_cancelled() -> bool``, polled as :meth:`Progress.cancelled`.
    stop_at_error : bool
        As :attr:`Progress.stop_at_error` (default False: errors propagate).
    """

    on_leg: Callable[[Leg], None] | None = None
    on_advance: Callable[[float, float], None] | None = None
    is_cancelled: Callable[[], bool] | None = None
    stop_at_error: bool = False

    def __post_init__(self) -> None:
        for name in ("on_leg", "on_advance", "is_cancelled"):
            value = getattr(self, name)
            if value is not None and not callable(value):
                raise InvalidInputError(
                    f"{name} must be a function or None, got {type(value).__name__} {value!r:.60}",
                    name,
                )
        flag(self.stop_at_error, "stop_at_error")

    def leg(self, leg: Leg) -> None:
        if self.on_leg is not None:
            self.on_leg(leg)

    def advance(self, done: float, total: float) -> None:
        if self.on_advance is not None:
            self.on_advance(done, total)

    def cancelled(self) -> bool:
        return self.is_cancelled is not None and bool(self.is_cancelled())


def stops_at(progress: Progress | None, error: JikError) -> bool:
    """Whether ``progress`` ends a run at ``error`` (:attr:`Progress.stop_at_error`) rather
    than let it propagate; False without a progress."""
    return progress is not None and bool(getattr(progress, "stop_at_error", False))


def part(progress: Progress | None, k: int, parts: int) -> Progress | None:
    """Piece ``k`` (from 0) of ``parts`` equal pieces of ``progress``'s work, as a Progress of
    its own: its ``advance(done, total)`` is ``progress.advance(k total + done, parts total)``,
    its ``cancelled()`` is ``progress``'s; None without a progress."""
    if progress is None:
        return None
    return ProgressCallbacks(
        on_advance=lambda done, total: progress.advance(k * total + done, parts * total),
        is_cancelled=progress.cancelled,
    )


def check_cancelled(progress: Progress | None, what: str) -> None:
    """Raise :class:`RunCancelled` ("<what>") when ``progress`` says the work is not wanted."""
    if progress is not None and progress.cancelled():
        raise RunCancelled(what)


def check_progress(progress: object, field: str = "progress") -> Progress | None:
    """``progress`` itself when it is None or a :class:`Progress`; otherwise an
    :class:`~jik.engine.exceptions.InvalidInputError` naming ``field`` (a plain function is
    wrapped by :class:`ProgressCallbacks`, which says which of its slots it fills)."""
    if progress is None or isinstance(progress, Progress):
        return progress
    raise InvalidInputError(
        f"{field} must be a Progress (subclass it and override leg, advance or cancelled) or "
        "ProgressCallbacks(on_leg=..., on_advance=..., is_cancelled=...) made of functions, "
        f"got {type(progress).__name__} {progress!r:.60}",
        field,
    )
