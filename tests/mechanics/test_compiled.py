"""The compiled (numba) kernels fill arrays with exactly the plain-Python equations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mdi_envs.mechanics.compiled import compile_equations
from mdi_envs.mechanics.models import BlockableManipulator, BouncingBall, SlidingBlock


def as_array(value: object, shape: tuple[int, ...]) -> np.ndarray:
    return np.array(value, dtype=float).reshape(shape)


# each model's eight kernels compile in the test (closures: not in the disk cache); the two
# larger models' compiles take minutes on a loaded machine
@pytest.mark.parametrize("model", [BouncingBall, pytest.param(SlidingBlock, marks=pytest.mark.slow),
                                   pytest.param(BlockableManipulator, marks=pytest.mark.slow)],
                         ids=lambda m: m.NAME)  # fmt: skip
def test_compiled_equals_plain_python(model: type) -> None:
    eq = compile_equations(model)
    assert compile_equations(model) is eq  # built once per class
    p = model.Parameters().values()
    n, m = model.NUM_DOFS, model.NUM_INPUTS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    rng = np.random.default_rng(0)
    for _ in range(20):
        q, u = rng.uniform(-3, 3, n), rng.normal(0, 4, n)
        out = {
            "mass": np.full((n, n), np.nan), "forces": np.full(n, np.nan),
            "inputs": np.full((n, m), np.nan), "gaps": np.full(c, np.nan),
            "contact_rows": np.full((c * d, n), np.nan), "brake_rows": np.full((k, n), np.nan),
            "restitutions": np.full(c, np.nan), "friction": np.full(c, np.nan),
        }  # fmt: skip
        eq.mass(q, p, out["mass"])
        eq.forces(q, u, p, out["forces"])
        eq.inputs(q, p, out["inputs"])
        eq.gaps(q, p, out["gaps"])
        eq.contact_rows(q, p, out["contact_rows"])
        eq.brake_rows(q, p, out["brake_rows"])
        eq.restitutions(p, out["restitutions"])
        eq.friction_coefficients(p, out["friction"])
        expected = {
            "mass": as_array(model.mass_matrix(q, p, math), (n, n)),
            "forces": as_array(model.forces(q, u, p, math), (n,)),
            "inputs": as_array(model.input_matrix(q, p, math), (n, m)),
            "gaps": as_array(model.gaps(q, p, math), (c,)),
            "contact_rows": as_array(model.contact_directions(q, p, math), (c * d, n)),
            "brake_rows": as_array(model.brake_directions(q, p, math), (k, n)),
            "restitutions": as_array(model.restitutions(p), (c,)),
            "friction": as_array(model.friction_coefficients(p), (c,)),
        }
        for name, value in expected.items():
            np.testing.assert_allclose(out[name], value, rtol=1e-15, atol=0, err_msg=name)
