"""Parameter validation helpers: every message names the field and the offending value."""

from __future__ import annotations

import math

import pytest

from mdi_envs.mechanics.parameters import (
    require_in_interval,
    require_nonnegative,
    require_positive,
)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, "1.0", None, True, [1.0]])
@pytest.mark.parametrize("check", [require_positive, require_nonnegative,
                                   lambda n, v: require_in_interval(n, v, 0.0, 1.0)])  # fmt: skip
def test_non_finite_or_non_numbers_are_rejected(check: object, bad: object) -> None:
    with pytest.raises(ValueError, match=r"parameter 'width' must be a finite number, got"):
        check("width", bad)  # type: ignore[operator]


def test_bounds() -> None:
    assert require_positive("a", 2) == 2.0 and isinstance(require_positive("a", 2), float)
    with pytest.raises(ValueError, match=r"parameter 'a' must be > 0, got 0"):
        require_positive("a", 0)
    assert require_nonnegative("b", 0.0) == 0.0
    with pytest.raises(ValueError, match=r"parameter 'b' must be >= 0, got -1e-300"):
        require_nonnegative("b", -1e-300)
    assert require_in_interval("c", 1.0, 0.0, 1.0) == 1.0
    assert require_in_interval("c", 0.0, 0.0, 1.0) == 0.0
    with pytest.raises(ValueError, match=r"parameter 'c' must lie in \[0, 1\], got 1.5"):
        require_in_interval("c", 1.5, 0.0, 1.0)
