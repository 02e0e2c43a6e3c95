"""Method registries: each solver method registers itself with its options type and a summary.

A driver (``solve_lcp``, ``solve_mlcp``, ``solve_fc3d``) owns one registry, looks the requested
method up by lowercase name (as ``scipy.optimize`` does) and builds its options from keyword
arguments, rejecting unknown names with a message that lists the valid ones.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Generic, TypeVar

import numpy as np


@dataclass(frozen=True)
class SolverOptions:
    """Options every iterative or pivoting method understands.

    Attributes:
        tol: tolerance on the problem type's shared residual measure (dimensionless).
        max_iter: iteration limit (sweeps, Newton steps or pivots, depending on the method).
        check_solution: recompute the shared residual after the method returns and downgrade a
            CONVERGED status to INACCURATE when it exceeds ``tol``. Switch off only on hot paths
            that check the solution themselves.
    """

    tol: float = 1e-10
    max_iter: int = 1000
    check_solution: bool = True

    def __post_init__(self) -> None:
        require_real_option(self, "tol", low=0.0, low_inclusive=False)
        require_integer_option(self, "max_iter", minimum=1)


def require_integer_option(options: object, name: str, minimum: int) -> None:
    """Raise ValueError unless option ``name`` is an integer (not a bool) >= ``minimum``."""
    value = getattr(options, name)
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"option {name!r} must be an integer >= {minimum}, got {value!r}")


def require_real_option(
    options: object,
    name: str,
    low: float = -np.inf,
    high: float = np.inf,
    low_inclusive: bool = True,
    high_inclusive: bool = True,
) -> None:
    """Raise ValueError unless option ``name`` is a finite real number in the given interval."""
    value = getattr(options, name)
    is_real = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, bool
    )
    inside = is_real and bool(np.isfinite(value))
    if inside:
        inside = (value >= low if low_inclusive else value > low) and (
            value <= high if high_inclusive else value < high
        )
    if not inside:
        interval = (
            f"{'[' if low_inclusive else '('}{low:g}, {high:g}{']' if high_inclusive else ')'}"
        )
        raise ValueError(f"option {name!r} must be a finite number in {interval}, got {value!r}")


OptionsT = TypeVar("OptionsT", bound=SolverOptions)


@dataclass(frozen=True)
class MethodSpec(Generic[OptionsT]):
    """A registered method: its solve function, options type and one-line summary."""

    name: str
    solve: Callable[..., Any]
    options_type: type[OptionsT]
    summary: str
    direct: Callable[..., Any] | None = None
    """Optional whole-driver path of the method, for drivers that offer one: screening, trivial
    cases, the method and the shared residual check in one compiled call (see ``solve_lcp``)."""

    def make_options(self, overrides: dict[str, Any]) -> OptionsT:
        """Build this method's options from keyword overrides.

        Raises:
            ValueError: an option name this method does not know (the valid names are listed),
                or an invalid option value.
        """
        if not overrides:
            return self.default_options
        valid = {f.name for f in dataclasses.fields(self.options_type)}
        unknown = sorted(set(overrides) - valid)
        if unknown:
            raise ValueError(
                f"unknown option(s) {unknown} for method {self.name!r}; "
                f"valid options: {sorted(valid)}"
            )
        return self.options_type(**overrides)

    @cached_property
    def default_options(self) -> OptionsT:
        """The method's options with every field at its default (built once)."""
        return self.options_type()


class MethodRegistry:
    """Name -> method table for one problem type (e.g. ``"LCP"``)."""

    def __init__(self, problem_name: str) -> None:
        self.problem_name = problem_name
        self._methods: dict[str, MethodSpec[Any]] = {}

    def register(
        self,
        name: str,
        options_type: type[SolverOptions],
        summary: str,
        direct: Callable[..., Any] | None = None,
    ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
        """Decorator registering ``solve`` under ``name`` with its options type and summary.

        ``direct``, if given, is the method's whole-driver path (see ``MethodSpec.direct``).
        """

        def decorator(solve: Callable[..., Any]) -> Callable[..., Any]:
            if name in self._methods:
                raise ValueError(f"{self.problem_name} method {name!r} registered twice")
            self._methods[name] = MethodSpec(name, solve, options_type, summary, direct)
            return solve

        return decorator

    def lookup(self, name: str) -> MethodSpec[Any]:
        """Return the method registered as ``name`` (case-insensitive, as in ``scipy.optimize``).

        Raises:
            ValueError: no such method; the message lists the valid names.
        """
        try:
            return self._methods[name.lower()]
        except (KeyError, TypeError, AttributeError):
            raise ValueError(
                f"unknown {self.problem_name} method {name!r}; valid methods: {self.names()}"
            ) from None

    def names(self) -> list[str]:
        """Registered method names, sorted."""
        return sorted(self._methods)

    def summaries(self) -> dict[str, str]:
        """Method name -> one-line description."""
        return {name: self._methods[name].summary for name in self.names()}


__all__ = [
    "MethodRegistry",
    "MethodSpec",
    "SolverOptions",
    "require_integer_option",
    "require_real_option",
]
