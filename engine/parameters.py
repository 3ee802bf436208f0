"""Scalar parameters with defaults and ranges, and their validation (robots, maps, inverses)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from .exceptions import InvalidInputError
from .validation import finite


@dataclass(frozen=True)
class Parameter:
    """A scalar parameter with its default and closed range [minimum, maximum]."""

    name: str
    default: float
    minimum: float
    maximum: float
    description: str
    nonzero: bool = False

    def check(self, value) -> float:
        """Validate ``value``; the message names the parameter and its range."""
        v = finite(value, self.name)
        if not self.minimum <= v <= self.maximum:
            raise InvalidInputError(
                f"{self.name} must be in [{self.minimum:g}, {self.maximum:g}], got {v:g}",
                self.name,
            )
        if self.nonzero and v == 0:
            raise InvalidInputError(f"{self.name} must be nonzero ({self.description})", self.name)
        return v

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "default": self.default,
            "minimum": self.minimum,
            "maximum": self.maximum,
            "description": self.description,
            "nonzero": self.nonzero,
        }


def check_params(
    specs: tuple[Parameter, ...],
    values: Mapping[str, object],
    what: str,
    vectors: tuple[str, ...] = (),
) -> dict:
    """Each parameter's value checked (its default where not given); an unknown name is
    refused naming every known one, the scalars ``specs`` and the ``vectors`` (checked by
    their owner); the error's field is the parameter's name (the first unknown one)."""
    known = {p.name for p in specs} | set(vectors)
    unknown = sorted(set(values) - known, key=str)
    if unknown:
        raise InvalidInputError(
            f"unknown parameter(s) {unknown} for {what}; known: {sorted(known) or 'none'}",
            str(unknown[0]),
        )
    return {p.name: p.check(values.get(p.name, p.default)) for p in specs}
