"""Validation of physical parameters: every message names the offending field and its value."""

from __future__ import annotations

import math


def _require_finite(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"parameter {name!r} must be a finite number, got {value!r}")
    return float(value)


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and > 0, else raise ValueError naming ``name``."""
    if _require_finite(name, value) <= 0.0:
        raise ValueError(f"parameter {name!r} must be > 0, got {value!r}")
    return float(value)


def require_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and >= 0, else raise ValueError."""
    if _require_finite(name, value) < 0.0:
        raise ValueError(f"parameter {name!r} must be >= 0, got {value!r}")
    return float(value)


def require_in_interval(name: str, value: float, low: float, high: float) -> float:
    """Return ``value`` as float if it is finite and in [low, high], else raise ValueError."""
    if not (low <= _require_finite(name, value) <= high):
        raise ValueError(f"parameter {name!r} must lie in [{low:g}, {high:g}], got {value!r}")
    return float(value)


__all__ = ["require_in_interval", "require_nonnegative", "require_positive"]
