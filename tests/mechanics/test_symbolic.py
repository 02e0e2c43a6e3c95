"""The symbolic (CasADi) and compiled (numba) evaluations of each model agree to round-off."""

from __future__ import annotations

import numpy as np
import pytest

from mdi_envs.mechanics import BlockableManipulator, BouncingBall, SlidingBlock
from mdi_envs.mechanics.compiled import compile_equations

casadi = pytest.importorskip("casadi")

from mdi_envs.mechanics.symbolic import symbolic_equations  # noqa: E402

MODELS = [BouncingBall, SlidingBlock, BlockableManipulator]


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.NAME)
def test_symbolic_equals_compiled_at_random_states(model: type) -> None:
    rng = np.random.default_rng(7)
    symbolic = symbolic_equations(model)
    compiled = compile_equations(model)
    p = model.Parameters().values()
    n, m = model.NUM_DOFS, model.NUM_INPUTS
    rows_c = model.NUM_CONTACTS * model.CONTACT_DIMENSION
    for _ in range(20):
        q, u = rng.uniform(-3.0, 3.0, n), rng.uniform(-5.0, 5.0, n)
        expected = {
            "mass": np.empty((n, n)), "forces": np.empty(n), "inputs": np.empty((n, m)),
            "gaps": np.empty(model.NUM_CONTACTS), "contact_rows": np.empty((rows_c, n)),
            "brake_rows": np.empty((model.NUM_BRAKES, n)),
        }
        compiled.mass(q, p, expected["mass"])
        compiled.forces(q, u, p, expected["forces"])
        compiled.inputs(q, p, expected["inputs"])
        compiled.gaps(q, p, expected["gaps"])
        compiled.contact_rows(q, p, expected["contact_rows"])
        compiled.brake_rows(q, p, expected["brake_rows"])
        for name, value in expected.items():
            function = getattr(symbolic, name)
            args = (q, u) if name == "forces" else (q,)
            got = np.array(function(*args), dtype=float).reshape(value.shape)
            np.testing.assert_allclose(got, value, rtol=1e-14, atol=1e-14, err_msg=name)


def test_symbolic_mass_matrix_has_exact_derivatives() -> None:
    """dM/dq by CasADi's AD equals the analytic derivative of the manipulator's coupling."""
    symbolic = symbolic_equations(BlockableManipulator)
    q = casadi.SX.sym("q", 2)
    dM12 = casadi.Function("dM12", [q], [casadi.jacobian(symbolic.mass(q)[0, 1], q)])
    p = BlockableManipulator.Parameters().values()
    c = 0.5 * p.link2_mass * p.link1_length * p.link2_length
    for alpha, beta in [(0.3, -1.2), (2.0, 0.5)]:
        expected = [c * np.sin(beta - alpha), -c * np.sin(beta - alpha)]
        np.testing.assert_allclose(np.array(dM12([alpha, beta])).ravel(), expected, atol=1e-14)
