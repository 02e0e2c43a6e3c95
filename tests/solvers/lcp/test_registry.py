"""The LCP method registry (``mdi_envs/solvers/lcp/registry.py``)."""

from __future__ import annotations

import dataclasses

import pytest

from mdi_envs.solvers import LCP_METHODS
from mdi_envs.solvers._registry import SolverOptions
from mdi_envs.solvers.lcp.enumerative import EnumerativeOptions, solve_enumerative
from mdi_envs.solvers.lcp.lemke import LemkeOptions, solve_lemke
from mdi_envs.solvers.lcp.newton_fb import NewtonFBOptions, solve_newton_fb
from mdi_envs.solvers.lcp.pgs import PGSOptions, solve_pgs

EXPECTED = {
    "enumerative": (solve_enumerative, EnumerativeOptions),
    "lemke": (solve_lemke, LemkeOptions),
    "newton_fb": (solve_newton_fb, NewtonFBOptions),
    "pgs": (solve_pgs, PGSOptions),
}


def test_every_method_is_registered_once_under_its_name() -> None:
    """Importing the package registers exactly the four methods."""
    assert LCP_METHODS.problem_name == "LCP"
    assert LCP_METHODS.names() == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_spec_points_at_the_method(name: str) -> None:
    """Each spec holds the module's solve function, its options type and a summary."""
    spec = LCP_METHODS.lookup(name)
    solve, options_type = EXPECTED[name]
    assert spec.name == name and spec.solve is solve and spec.options_type is options_type
    assert issubclass(options_type, SolverOptions)
    assert spec.summary and spec.summary == LCP_METHODS.summaries()[name]
    fields = {f.name for f in dataclasses.fields(options_type)}
    assert {"tol", "max_iter", "check_solution"} <= fields


def test_registering_a_name_twice_is_refused() -> None:
    """A second registration under an existing name is a programming error."""
    with pytest.raises(ValueError, match="LCP method 'lemke' registered twice"):
        LCP_METHODS.register("lemke", LemkeOptions, "duplicate")(solve_lemke)
    assert LCP_METHODS.lookup("lemke").solve is solve_lemke
