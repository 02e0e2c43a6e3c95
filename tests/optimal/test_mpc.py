"""The shrinking-horizon MPC on a short manipulator problem (N = 40, h ~ 0.11 s).

The tests on the solved reference re-plan with IPOPT at every step: marked slow (`make test`
runs them, the `not slow` inner loop does not).
"""

from __future__ import annotations

import numpy as np
import pytest

casadi = pytest.importorskip("casadi")

from mdi_envs.rollout import rollout  # noqa: E402
from optimal.continuation import solve_continuation  # noqa: E402
from optimal.modes import ModePattern  # noqa: E402
from optimal.mpc import (  # noqa: E402
    GRID_OF_REFERENCE,
    NEIGHBOUR_WINDOW,
    Plan,
    ShrinkingHorizonMPC,
    _imminent_neighbours,
    reference_plan,
)
from optimal.problems import make_problem  # noqa: E402
from optimal.references import Reference  # noqa: E402
from optimal.replay import env_options  # noqa: E402
from optimal.solution import read_solution  # noqa: E402
from optimal.transcription import Transcription  # noqa: E402

SHORT_N = 40


@pytest.fixture(scope="module")
def short_reference() -> Reference:
    """The N = 40 manipulator optimum of the continuation from the naive guess (~2 s)."""
    problem = make_problem("manipulator_time", SHORT_N)
    transcription = Transcription(problem)
    result = solve_continuation(transcription)
    assert result.success
    arrays, final_time = read_solution(result.transcription or transcription, result.values)
    return Reference("manipulator_time", arrays, {
        "final_time": final_time, "time_step": final_time / SHORT_N,
        "torque_bound": problem.torque_bound, "env_id": problem.env_id, "cost_kind": "time",
        "env_kwargs": {}})


@pytest.fixture(scope="module")
def controller(short_reference) -> ShrinkingHorizonMPC:  # noqa: ANN001
    """One env-grid controller for the module's episodes: each test resets it first.

    Its NLPs (one per horizon and pattern) are built once and shared by the episodes;
    ``test_a_second_episode_reuses_the_built_nlps`` checks that a reset controller replays an
    episode exactly.
    """
    return ShrinkingHorizonMPC(short_reference)


def _play(controller: ShrinkingHorizonMPC, noise: float, seed: int) -> dict:
    """A new episode of ``controller`` from a start perturbed at ``noise``: its last info."""
    reference = controller.reference
    options = env_options(reference)
    options.update(reset_noise_scale=noise, max_episode_steps=2 * SHORT_N)
    controller.reset()
    return rollout(reference.metadata["env_id"], controller, seed=seed, **options).last_info


@pytest.fixture(scope="module")
def perturbed_episode(controller: ShrinkingHorizonMPC) -> tuple[dict, list]:
    """One episode from a start perturbed at 0.01 (seed 1): its last info and step records."""
    info = _play(controller, 0.01, 1)
    return info, controller.steps


@pytest.mark.slow
def test_mpc_from_the_nominal_start_follows_the_reference(
        short_reference, controller: ShrinkingHorizonMPC) -> None:  # noqa: ANN001
    info = _play(controller, 0.0, 0)
    assert info["is_success"]
    # the env stops at the goal's tolerance box, at the optimum's t_f at the latest
    assert info["elapsed_time"] <= short_reference.final_time + 1e-9
    first = controller.steps[0]
    assert first.fallback == "" and first.horizon == SHORT_N
    assert first.cost == pytest.approx(short_reference.final_time, rel=1e-6)


@pytest.mark.slow
def test_mpc_reaches_the_goal_from_a_perturbed_start(short_reference, perturbed_episode) -> None:  # noqa: ANN001
    info, steps = perturbed_episode
    assert info["is_success"]
    assert info["elapsed_time"] <= 1.05 * short_reference.final_time
    assert all(step.compute_time > 0.0 for step in steps)


@pytest.mark.slow
def test_a_second_episode_reuses_the_built_nlps(controller: ShrinkingHorizonMPC,
                                                perturbed_episode) -> None:  # noqa: ANN001
    first_info, first_steps = perturbed_episode
    built = controller.nlps_built
    info = _play(controller, 0.01, 1)
    assert controller.nlps_built == built  # every (intervals, pattern) of the replay was kept
    assert info["elapsed_time"] == first_info["elapsed_time"]
    np.testing.assert_allclose([s.cost for s in controller.steps],
                               [s.cost for s in first_steps], rtol=1e-6)


def test_plan_shift_delay_and_regrid_keep_the_trajectory() -> None:
    time = np.linspace(0.0, 1.0, 5)
    q = np.column_stack([time, time**2])
    plan = Plan(q, q.copy(), np.arange(4.0)[:, None],
                ModePattern(engaged=np.array([[False, True, True, False]])), 1.0)
    rest = plan.shifted()
    assert rest.num_intervals == 3 and rest.final_time == pytest.approx(0.75)
    np.testing.assert_array_equal(rest.q, q[1:])
    assert rest.modes.engaged.tolist() == [[True, True, False]]
    later = plan.delayed(2)
    assert later.num_intervals == 6 and later.final_time == pytest.approx(1.5)
    np.testing.assert_array_equal(later.q, q[[0, 0, 0, 1, 2, 3, 4]])
    assert later.tau[:, 0].tolist() == [0, 0, 0, 1, 2, 3]
    assert later.modes.engaged.tolist() == [[False, False, False, True, True, False]]
    fine = plan.regridded(8)
    np.testing.assert_allclose(fine.q[::2], q)
    assert fine.tau[:, 0].tolist() == [0, 0, 1, 1, 2, 2, 3, 3]
    last = Plan(q[-2:], q[-2:], np.ones((1, 1)), ModePattern(engaged=np.array([[True]])), 0.25)
    held = last.shifted()
    assert held.num_intervals == 1 and np.allclose(held.q, q[-1])
    assert last.shifted(2).num_intervals == 2


def test_the_neighbour_fallback_moves_only_imminent_modes() -> None:
    sliding = np.zeros((2, 12), dtype=bool)
    sliding[0, 2:6] = True  # a switch inside the window and one beyond it
    sliding[1, 8:] = True  # switches only beyond it
    modes = ModePattern(sliding=sliding)
    kept = _imminent_neighbours(modes)
    kept_keys = {pattern.key() for pattern in kept}
    assert kept
    for _, pattern in modes.neighbours(max_shift=1):
        changed = np.flatnonzero((pattern.sliding != sliding).any(axis=0))
        assert (pattern.key() in kept_keys) == (changed.min() < NEIGHBOUR_WINDOW)


@pytest.mark.slow
def test_every_time_plan_is_on_the_env_grid(controller: ShrinkingHorizonMPC,
                                            perturbed_episode) -> None:  # noqa: ANN001
    """t_f = N h: each plan arrives at the end of an env step, and shrinks by one step."""
    info, steps = perturbed_episode
    h = controller.time_step
    assert info["is_success"]
    for step in steps:
        assert step.cost == pytest.approx(step.horizon * h, rel=1e-6)  # IPOPT's bound relax
    assert [step.horizon for step in steps] == list(range(SHORT_N, SHORT_N - len(steps), -1))


@pytest.mark.slow
def test_a_start_needing_more_steps_than_left_gets_them(
        short_reference, controller: ShrinkingHorizonMPC) -> None:  # noqa: ANN001
    """From the reference's start with two steps fewer left than it needs: two steps later."""
    controller.reset()
    controller._plan = reference_plan(short_reference).shifted()  # next guess: N - 2
    controller.control(short_reference.q[0], short_reference.u[0])
    step = controller.steps[-1]
    assert step.fallback == "2 step(s) later" and step.horizon == SHORT_N
    assert step.cost == pytest.approx(short_reference.final_time, rel=1e-6)


@pytest.mark.slow
def test_a_free_grid_plan_slightly_slower_than_h_still_shrinks(short_reference) -> None:  # noqa: ANN001
    """The rest keeps N - 1 intervals within ``REGRID_TOLERANCE`` of h; re-grids beyond."""
    controller = ShrinkingHorizonMPC(short_reference, grid="free")
    h = controller.time_step

    def plan(num_intervals: int, interval: float) -> Plan:
        q = np.zeros((num_intervals + 1, 2))
        return Plan(q, q.copy(), np.zeros((num_intervals, 1)),
                    ModePattern(engaged=np.zeros((1, num_intervals), dtype=bool)),
                    num_intervals * interval)

    # intervals 0.7 % longer than h: rounding alone gives 97 again, the next switch never nears
    assert round(96 * 1.007) == 97
    assert controller._horizon_after_step(plan(97, 1.007 * h)) == 96
    # intervals more than REGRID_TOLERANCE off h: re-gridded to steps of h
    assert controller._horizon_after_step(plan(20, 1.4 * h)) == 27  # 19 x 1.4 = 26.6
    assert controller._horizon_after_step(plan(20, 0.6 * h)) == 11  # 19 x 0.6 = 11.4
    assert controller._horizon_after_step(plan(1, h)) == 1  # held at min_horizon


@pytest.mark.slow
def test_the_free_grid_mpc_reaches_the_goal(short_reference) -> None:  # noqa: ANN001
    options = env_options(short_reference)
    options.update(reset_noise_scale=0.01, max_episode_steps=2 * SHORT_N)
    controller = ShrinkingHorizonMPC(short_reference, grid="free")
    result = rollout(short_reference.metadata["env_id"], controller, seed=1, **options)
    assert result.last_info["is_success"]
    assert any(step.horizon != SHORT_N - step.step for step in controller.steps)  # re-gridded


@pytest.mark.slow
def test_the_grid_is_chosen_per_reference_and_checked(short_reference) -> None:  # noqa: ANN001
    assert ShrinkingHorizonMPC(short_reference).grid == GRID_OF_REFERENCE["manipulator_time"]
    with pytest.raises(ValueError, match="grid must be one of"):
        ShrinkingHorizonMPC(short_reference, grid="fine")
