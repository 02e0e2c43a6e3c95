"""The compiled angle helpers the env kernels use, against numpy."""

from __future__ import annotations

import math

import numpy as np

from mdi_envs.angles import cos_sin, wrap_angle

ANGLES = np.concatenate([np.random.default_rng(0).uniform(-1e3, 1e3, 500),
                         [0.0, -0.0, math.pi, -math.pi, 1e-300, 2.5e7]])  # fmt: skip


def test_cos_sin_equals_cos_and_sin() -> None:
    values = np.array([cos_sin(angle) for angle in ANGLES])
    np.testing.assert_allclose(values[:, 0], np.cos(ANGLES), rtol=0, atol=4e-16)
    np.testing.assert_allclose(values[:, 1], np.sin(ANGLES), rtol=0, atol=4e-16)


def test_wrap_angle_lands_in_minus_pi_pi_on_the_same_direction() -> None:
    wrapped = np.array([wrap_angle(angle) for angle in ANGLES])
    assert np.all(np.abs(wrapped) <= math.pi)
    turns = (ANGLES - wrapped) / (2 * math.pi)
    np.testing.assert_allclose(turns, np.round(turns), rtol=0, atol=1e-9)
