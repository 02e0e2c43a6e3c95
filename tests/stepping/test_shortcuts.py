"""Each exact shortcut of the step gives the full path's trajectory to round-off."""

from __future__ import annotations

import numpy as np
import pytest

from mdi_envs.mechanics import BlockableManipulator, BouncingBall, SlidingBlock
from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters
from mdi_envs.stepping import MoreauJeanStepper, StepShortcuts


def _rollout(stepper: MoreauJeanStepper, q0: list[float], pushes: np.ndarray,
             brakes: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, list[int]]:
    q, u = np.array(q0, dtype=float), np.zeros(len(q0))
    states, impulses, lcp_sizes = [], [], []
    for k, tau in enumerate(pushes):
        result = stepper.step(q, u, [tau], None if brakes is None else [brakes[k]])
        q, u = result.q, result.u
        states.append(np.concatenate([q, u]))
        impulses.append(result.impulses)
        lcp_sizes.append(result.lcp_size)
    return np.array(states), np.array(impulses), lcp_sizes


def test_frictionless_contact_drops_its_friction_rows() -> None:
    """With mu = 0 the normal row alone equals the full (P_N, P_R, xi_L) LCP with P_T = 0."""
    pushes = 0.3 * np.sin(np.linspace(0.0, 20.0, 3000))
    params = BouncingBallParameters(restitution=0.6)
    short = MoreauJeanStepper(BouncingBall, params, 1e-3)
    full = MoreauJeanStepper(BouncingBall, params, 1e-3,
                             StepShortcuts(skip_frictionless_rows=False))
    s_states, s_imp, s_sizes = _rollout(short, [0.0, 0.5], pushes)
    f_states, f_imp, f_sizes = _rollout(full, [0.0, 0.5], pushes)
    np.testing.assert_allclose(s_states, f_states, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(s_imp, f_imp, rtol=0.0, atol=1e-12)
    assert max(s_sizes) == 1 and max(f_sizes) == 3  # the shortcut really was taken


@pytest.mark.parametrize("model", [BouncingBall, SlidingBlock])
def test_constant_mass_matrix_is_inverted_once(model: type) -> None:
    pushes = np.linspace(-2.0, 2.0, 2000)
    once = MoreauJeanStepper(model, time_step=1e-3)
    every = MoreauJeanStepper(model, time_step=1e-3,
                              shortcuts=StepShortcuts(reuse_constant_mass=False))
    q0 = [0.0, 0.3] if model is BouncingBall else [0.0, 0.0]
    np.testing.assert_allclose(_rollout(once, q0, pushes)[0], _rollout(every, q0, pushes)[0],
                               rtol=0.0, atol=1e-13)


def test_tiny_lcp_by_enumeration_equals_lemke() -> None:
    """The block's stick-slip LCP (size 3) solved directly and by Lemke's method."""
    pushes = 8.0 * np.sin(np.linspace(0.0, 12.0, 3000))
    direct = MoreauJeanStepper(SlidingBlock, time_step=1e-3)
    lemke = MoreauJeanStepper(SlidingBlock, time_step=1e-3,
                              shortcuts=StepShortcuts(direct_solve_max_size=0))
    d_states, d_imp, sizes = _rollout(direct, [0.0, 0.0], pushes)
    l_states, l_imp, _ = _rollout(lemke, [0.0, 0.0], pushes)
    assert max(sizes) == 3
    np.testing.assert_allclose(d_states, l_states, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(d_imp, l_imp, rtol=0.0, atol=1e-12)


def test_released_brake_and_open_contacts_solve_nothing() -> None:
    """No closed contact and no engaged brake: no complementarity problem at all."""
    ball = MoreauJeanStepper(BouncingBall, time_step=1e-3).step([0.0, 1.0], [0.0, 0.0], [0.0])
    arm = MoreauJeanStepper(BlockableManipulator, time_step=1e-3).step(
        [0.0, 0.0], [1.0, -1.0], [0.5], [0.0]
    )
    for result in (ball, arm):
        assert (result.lcp_size, result.num_equalities, result.num_iter) == (0, 0, 0)
        assert not result.impulses.any()


def test_single_row_closed_form_equals_the_mlcp() -> None:
    """One active row in closed form equals its MLCP.

    An engaged brake (ideal or Tresca) or a frictionless contact: same trajectory, impulses
    and problem sizes.
    """
    steps = 3000
    torques = 2.0 * np.sign(np.sin(np.linspace(0.0, 9.0, steps)))
    brakes = np.where(np.arange(steps) % 700 < 300, np.inf, 0.0)
    brakes[1500:2100] = np.where(brakes[1500:2100] > 0.0, 0.4, 0.0)  # Tresca phases
    arm_closed = MoreauJeanStepper(BlockableManipulator, time_step=1e-3)
    arm_mlcp = MoreauJeanStepper(BlockableManipulator, time_step=1e-3,
                                 shortcuts=StepShortcuts(closed_form_single_row=False))
    ball_pushes = 0.3 * np.sin(np.linspace(0.0, 20.0, steps))
    params = BouncingBallParameters(restitution=0.6)
    ball_closed = MoreauJeanStepper(BouncingBall, params, 1e-3)
    ball_mlcp = MoreauJeanStepper(BouncingBall, params, 1e-3,
                                  StepShortcuts(closed_form_single_row=False))
    for closed, mlcp, q0, pushes, brake in (
        (arm_closed, arm_mlcp, [0.0, 0.3], torques, brakes),
        (ball_closed, ball_mlcp, [0.0, 0.5], ball_pushes, None),
    ):
        c_states, c_imp, c_sizes = _rollout(closed, q0, pushes, brake)
        m_states, m_imp, m_sizes = _rollout(mlcp, q0, pushes, brake)
        np.testing.assert_allclose(c_states, m_states, rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(c_imp, m_imp, rtol=0.0, atol=1e-12)
        assert c_sizes == m_sizes
        assert np.abs(c_imp).max() > 0.0  # rows were active
        if closed is arm_closed:
            assert {0, 2} <= set(c_sizes)  # ideal brake / released (0) and Tresca (2) taken
