"""Method registries and common options (``mdi_envs/solvers/_registry.py``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import pytest

from mdi_envs.solvers import LCP_METHODS
from mdi_envs.solvers._registry import MethodRegistry, MethodSpec, SolverOptions


@dataclass(frozen=True)
class _CountingOptions(SolverOptions):
    """Options that count their constructions (to observe caching)."""

    gain: float = 1.0
    built: ClassVar[int] = 0

    def __post_init__(self) -> None:
        super().__post_init__()
        type(self).built += 1
        if not self.gain > 0:
            raise ValueError(f"option 'gain' must be > 0, got {self.gain!r}")


def _solve(*args: Any) -> str:
    return "solved"


def _other(*args: Any) -> str:
    return "other"


@pytest.fixture
def registry() -> MethodRegistry:
    """A fresh registry with two methods, independent of the package's registries."""
    table = MethodRegistry("TOY")
    table.register("beta", _CountingOptions, "second method")(_solve)
    table.register("alpha", SolverOptions, "first method")(_other)
    return table


def test_register_returns_the_function_unchanged(registry: MethodRegistry) -> None:
    """The decorator registers and hands the function back."""

    def gamma(*args: Any) -> None:
        return None

    assert registry.register("gamma", SolverOptions, "third")(gamma) is gamma
    assert registry.lookup("gamma").solve is gamma


def test_names_and_summaries_are_sorted(registry: MethodRegistry) -> None:
    """Names come back sorted whatever the registration order."""
    assert registry.names() == ["alpha", "beta"]
    assert registry.summaries() == {"alpha": "first method", "beta": "second method"}


def test_lookup_returns_the_spec(registry: MethodRegistry) -> None:
    """A spec bundles name, solve function, options type and summary."""
    spec = registry.lookup("beta")
    assert isinstance(spec, MethodSpec)
    assert (spec.name, spec.solve, spec.options_type, spec.summary) == (
        "beta",
        _solve,
        _CountingOptions,
        "second method",
    )


@pytest.mark.parametrize("name", ["gamma", "", "alpha ", None, 1, ("alpha",), ["alpha"], {}])
def test_unknown_name_lists_the_valid_ones(registry: MethodRegistry, name: object) -> None:
    """Unknown (or unhashable) names raise ValueError naming the problem type and valid names."""
    with pytest.raises(ValueError, match="unknown TOY method") as info:
        registry.lookup(name)
    assert str(info.value).endswith("valid methods: ['alpha', 'beta']")


def test_duplicate_registration_is_refused(registry: MethodRegistry) -> None:
    """Registering a taken name raises and keeps the original."""
    with pytest.raises(ValueError, match="TOY method 'alpha' registered twice"):
        registry.register("alpha", SolverOptions, "again")(_solve)
    assert registry.lookup("alpha").solve is _other


def test_lookup_is_case_insensitive_as_documented() -> None:
    """The module docstring: methods are looked up "by lowercase name (as scipy.optimize does)".

    ``scipy.optimize.minimize(method="BFGS")`` works because scipy lower-cases the request.
    """
    assert LCP_METHODS.lookup("Lemke") is LCP_METHODS.lookup("lemke")
    assert LCP_METHODS.lookup("PGS") is LCP_METHODS.lookup("pgs")


def test_default_options_are_built_once_and_shared(registry: MethodRegistry) -> None:
    """No overrides: the cached default instance, constructed a single time."""
    spec = registry.lookup("beta")
    before = _CountingOptions.built
    first = spec.make_options({})
    second = spec.make_options({})
    assert first is second is spec.default_options
    assert _CountingOptions.built == before + 1
    assert first == _CountingOptions()


def test_overrides_build_a_new_instance(registry: MethodRegistry) -> None:
    """Overrides produce fresh options with those values; the cached default is untouched."""
    spec = registry.lookup("beta")
    options = spec.make_options({"gain": 2.5, "tol": 1e-6})
    assert (options.gain, options.tol, options.max_iter) == (2.5, 1e-6, 1000)
    assert spec.default_options.gain == 1.0 and options is not spec.default_options


def test_unknown_option_lists_the_valid_ones(registry: MethodRegistry) -> None:
    """Unknown option names raise ValueError with the sorted valid names of that method."""
    spec = registry.lookup("beta")
    with pytest.raises(ValueError) as info:
        spec.make_options({"gian": 2.0, "zeta": 1, "tol": 1e-3})
    assert str(info.value) == (
        "unknown option(s) ['gian', 'zeta'] for method 'beta'; "
        "valid options: ['check_solution', 'gain', 'max_iter', 'tol']"
    )


def test_invalid_option_value_propagates(registry: MethodRegistry) -> None:
    """A value the options type rejects surfaces as its ValueError."""
    with pytest.raises(ValueError, match="option 'gain' must be > 0"):
        registry.lookup("beta").make_options({"gain": -1.0})


def test_package_default_options_are_cached() -> None:
    """The LCP methods' default options are built once per method."""
    for name in LCP_METHODS.names():
        spec = LCP_METHODS.lookup(name)
        assert spec.make_options({}) is spec.default_options is spec.default_options


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"tol": 0.0}, "option 'tol' must be a finite number in \\(0, inf\\], got 0.0"),
        ({"tol": -1.0}, "option 'tol' must be a finite number in \\(0, inf\\]"),
        ({"tol": float("nan")}, "option 'tol' must be a finite number in \\(0, inf\\]"),
        ({"max_iter": 0}, "option 'max_iter' must be an integer >= 1, got 0"),
        ({"max_iter": -3}, "option 'max_iter' must be an integer >= 1"),
        ({"max_iter": 2.5}, "option 'max_iter' must be an integer >= 1"),
        # Non-finite counts must fail the same way (today: OverflowError / int()'s message).
        ({"max_iter": float("inf")}, "option 'max_iter' must be an integer >= 1"),
        ({"max_iter": float("nan")}, "option 'max_iter' must be an integer >= 1"),
    ],
    ids=[
        "tol_0", "tol_negative", "tol_nan", "max_iter_0", "max_iter_negative", "max_iter_2.5",
        "max_iter_inf", "max_iter_nan",
    ],
)
def test_solver_options_validation(kwargs: dict[str, float], match: str) -> None:
    """SolverOptions rejects non-positive tolerances and non-positive/non-integer limits."""
    with pytest.raises(ValueError, match=match):
        SolverOptions(**kwargs)


def test_solver_options_defaults() -> None:
    """Documented defaults."""
    options = SolverOptions()
    assert (options.tol, options.max_iter, options.check_solution) == (1e-10, 1000, True)
