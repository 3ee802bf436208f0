"""Typed errors of the engine.

Every error says what is wrong and how to fix it; the singular ones carry the configuration.
"""

from __future__ import annotations

import numpy as np


class JikError(Exception):
    """Base class of every error raised by jik (a cancellation is no error: see RunCancelled)."""


class InvalidInputError(JikError, ValueError):
    """An argument has the wrong shape, a non-finite value or an out-of-range parameter.

    Parameters
    ----------
    message : str
        What is wrong and how to fix it.
    field : str, optional
        The input it is about, as a dotted path (``"gamma"``, ``"robot_parameters.l"``), when
        the raiser knows it: a web client maps the error to that field without reading the text.
    """

    def __init__(self, message: str, field: str | None = None) -> None:
        super().__init__(message)
        self.field = field


class FormulaError(InvalidInputError):
    """A formula that the whitelist grammar refuses (:mod:`jik.engine.formula`).

    Parameters
    ----------
    message : str
        What is wrong, naming the field and the position.
    field : str, optional
        As for :class:`InvalidInputError` (``"task.0"``, ``"augmentation.h"``).
    position : int, optional
        0-based index of the offending character in the formula's text, for an editor to mark.
    """

    def __init__(self, message: str, field: str | None = None, position: int | None = None):
        super().__init__(message, field)
        self.position = position


class SingularConfigurationError(JikError):
    """The configuration is a kinematic or algorithmic singularity.

    Parameters
    ----------
    message : str
        What is singular and what to do about it.
    configuration : array_like, shape (p,)
        The offending configuration.
    field : str, optional
        The input it came from, as :class:`InvalidInputError`'s ``field``: ``"x0"`` a solve's
        start, ``"region"`` a point of a synthesis region, ``"x"`` the argument of an inverse's
        ``apply`` or ``matrix``; a web client marks that input.
    """

    def __init__(self, message: str, configuration, field: str | None = None) -> None:
        self.configuration = np.asarray(configuration, dtype=float)
        self.field = field
        super().__init__(f"{message} at x = {format_vector(self.configuration)}")

    def __reduce__(self):
        """Pickled as its class, message and attributes, so that the error of a worker process
        reaches its parent whole (``__init__`` wants the configuration, and would add it to the
        message a second time)."""
        return _unpickled, (type(self), self.args), self.__dict__


class KinematicSingularityError(SingularConfigurationError):
    """The Jacobian J(x) loses rank: m(x) = sqrt(det J J^T) vanishes (eq. (8) undefined)."""


class AlgorithmicSingularityError(SingularConfigurationError):
    """The extended Jacobian [J; dh] is singular: eq. (11) undefined."""


class OneFormUndefinedError(SingularConfigurationError):
    """The normalised one-form omega (omega J^T = 0) cannot be normalised (section 4)."""


class RunCancelled(Exception):
    """The caller's ``cancelled()`` said so: a long run stopped between two of its solves.

    Not a :class:`JikError`: nothing is wrong with the run's input, and code that turns engine
    errors into failed results (a leg that stops a run, an HTTP 422) must let it through.
    """


def _unpickled(cls: type[SingularConfigurationError], args: tuple) -> SingularConfigurationError:
    """An error of ``cls`` with its ``args`` as they were; pickle then sets its attributes."""
    error = Exception.__new__(cls)
    error.args = args
    return error


def format_vector(v) -> str:
    """Short readable form of a vector for error messages."""
    v = np.atleast_1d(np.asarray(v, dtype=float))
    return "(" + ", ".join(f"{t:.6g}" for t in v.ravel()) + ")"
