"""Moreau-Jean stepping of the bouncing ball against its closed forms (docs/theory.md).

The ball is dropped from rest at height h0 above contact (gap g = y - r = h0). Closed forms with
v1 = sqrt(2 g h0): first impact at t1 = sqrt(2 h0 / g), then impacts spaced 2 eps^k v1 / g,
apex heights eps^(2k) h0, and (eps < 1) rest at the Zeno time t_inf = t1 (1 + eps) / (1 - eps).

The midpoint step integrates free flight exactly (constant acceleration), so every error comes
from where the impact falls inside a step: it is O(dt) with a coefficient that depends on the
phase of the impact within the step. To measure a convergence *ratio*, errors are therefore
averaged over an ensemble of 48 drop heights drawn at random (fixed seed), whose phases are
spread over the step (an evenly spaced grid of heights aliases with the time step); bounds are
checked for every member.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pytest

from mdi_envs.mechanics.models import BouncingBall
from mdi_envs.stepping import MoreauJeanStepper

GRAVITY = 9.81
RADIUS = 0.05
MASS = 0.1
HEIGHTS = np.random.default_rng(0).uniform(0.9, 1.1, 48)  # drop heights h0 above contact [m]
TIME_STEPS = (4e-3, 2e-3, 1e-3)
ZENO_HEIGHTS = HEIGHTS[:12]  # the long runs (Zeno, energy) use fewer heights
NUM_BOUNCES = 4  # impacts 0..4 and apexes 1..4 compared with the closed form


class Drop(NamedTuple):
    """Trajectories of an ensemble of drops: rows are grid times, columns drop heights."""

    dt: float
    y: np.ndarray  # (N + 1, C) heights of the centre
    v: np.ndarray  # (N + 1, C) vertical velocities
    p_n: np.ndarray  # (N, C) normal impulse of each step
    p_t: np.ndarray  # (N, C) tangential impulse of each step


def drop(stepper: MoreauJeanStepper, heights: np.ndarray, t_end: float) -> Drop:
    """Drop balls from rest at gap ``heights``, record every step up to ``t_end``."""
    dt = stepper.time_step
    num_steps = int(np.ceil(t_end / dt))
    q = np.column_stack([np.zeros_like(heights), RADIUS + heights])
    u = np.zeros_like(q)
    tau = np.zeros((len(heights), 1))
    y = np.empty((num_steps + 1, len(heights)))
    v = np.empty_like(y)
    p_n = np.empty((num_steps, len(heights)))
    p_t = np.empty_like(p_n)
    y[0], v[0] = q[:, 1], u[:, 1]
    for i in range(num_steps):
        impulses, _ = stepper.step_batch(q, u, tau)
        y[i + 1], v[i + 1] = q[:, 1], u[:, 1]
        p_n[i], p_t[i] = impulses[:, 0], impulses[:, 1]
    return Drop(dt, y, v, p_n, p_t)


def first_impact(h0: np.ndarray) -> np.ndarray:
    return np.sqrt(2.0 * h0 / GRAVITY)


def zeno_time(h0: np.ndarray, eps: float) -> np.ndarray:
    return first_impact(h0) * (1.0 + eps) / (1.0 - eps)


def impact_times(h0: float, eps: float, count: int) -> np.ndarray:
    """Closed-form times of the first ``count`` impacts."""
    v1 = np.sqrt(2.0 * GRAVITY * h0)
    times = [float(first_impact(np.asarray(h0)))]
    for k in range(1, count):
        times.append(times[-1] + 2.0 * eps**k * v1 / GRAVITY)
    return np.array(times)


def impact_steps(p_n: np.ndarray) -> np.ndarray:
    """Indices of the steps that start an impact (impulse after an impulse-free step)."""
    hit = p_n > 0.0
    return np.nonzero(hit & ~np.concatenate([[False], hit[:-1]]))[0]


@pytest.fixture(scope="module")
def drops(make_stepper: Callable[..., MoreauJeanStepper]) -> dict[float, Drop]:
    """Default ball (eps = 0.8), all heights, until just past impact 4, at each time step."""
    t_end = 1.05 * impact_times(HEIGHTS.max(), 0.8, NUM_BOUNCES + 1)[-1]
    return {dt: drop(make_stepper(BouncingBall, dt), HEIGHTS, t_end) for dt in TIME_STEPS}


@pytest.fixture(scope="module")
def zeno_drops(make_stepper: Callable[..., MoreauJeanStepper]) -> dict[float, Drop]:
    """Default ball (eps = 0.8), heights ZENO_HEIGHTS, for 2 t_inf, at each time step."""
    t_end = 2.0 * float(zeno_time(ZENO_HEIGHTS.max(), 0.8))
    return {dt: drop(make_stepper(BouncingBall, dt), ZENO_HEIGHTS, t_end) for dt in TIME_STEPS}


def bounce_errors(run: Drop, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Per drop height: max |impact time error| and max |apex height error| over the bounces."""
    time_errors, apex_errors = [], []
    for c, h0 in enumerate(HEIGHTS):
        starts = impact_steps(run.p_n[:, c])[: NUM_BOUNCES + 1]
        assert len(starts) == NUM_BOUNCES + 1
        # The impulse acts at the step's midpoint: estimate the impact time there.
        measured = (starts + 0.5) * run.dt
        time_errors.append(np.abs(measured - impact_times(h0, eps, NUM_BOUNCES + 1)).max())
        apexes = np.array([run.y[a + 1 : b + 1, c].max() - RADIUS
                           for a, b in zip(starts[:-1], starts[1:], strict=True)])  # fmt: skip
        expected = h0 * eps ** (2.0 * np.arange(1, NUM_BOUNCES + 1))
        apex_errors.append(np.abs(apexes - expected).max())
    return np.array(time_errors), np.array(apex_errors)


def test_default_parameters_match_the_docs() -> None:
    p = BouncingBall.Parameters()
    assert (p.mass, p.radius, p.gravity, p.restitution) == (MASS, RADIUS, GRAVITY, 0.8)


def test_free_flight_is_exact_before_the_first_impact(drops: dict[float, Drop]) -> None:
    """Midpoint q, explicit u: constant acceleration is integrated exactly at grid times."""
    run = drops[1e-3]
    t = np.arange(run.y.shape[0]) * run.dt
    before = t < first_impact(HEIGHTS.min()) - 2 * run.dt
    expected = RADIUS + HEIGHTS[None, :] - 0.5 * GRAVITY * t[before, None] ** 2
    np.testing.assert_allclose(run.y[before], expected, rtol=0, atol=1e-12)
    expected_v = np.broadcast_to(-GRAVITY * t[before, None], run.v[before].shape)
    np.testing.assert_allclose(run.v[before], expected_v, rtol=0, atol=1e-12)
    assert np.all(run.p_n[before[:-1]] == 0.0)


def test_impact_times_converge_at_first_order(drops: dict[float, Drop]) -> None:
    """Impacts 0..4 against t1 + sum 2 eps^k v1 / g: error <= 5 dt, halving with dt."""
    means = []
    for dt in TIME_STEPS:
        time_errors, _ = bounce_errors(drops[dt], 0.8)
        assert time_errors.max() <= 5.0 * dt, (dt, time_errors.max())
        means.append(time_errors.mean())
    ratios = np.array(means[:-1]) / np.array(means[1:])
    assert np.all((ratios > 1.7) & (ratios < 2.4)), (means, ratios)


def test_apex_heights_converge_at_first_order(drops: dict[float, Drop]) -> None:
    """Apex k against eps^(2k) h0: error <= 0.6 v1 dt, halving with dt."""
    v1 = np.sqrt(2.0 * GRAVITY * HEIGHTS.max())
    means = []
    for dt in TIME_STEPS:
        _, apex_errors = bounce_errors(drops[dt], 0.8)
        assert apex_errors.max() <= 0.6 * v1 * dt, (dt, apex_errors.max())
        means.append(apex_errors.mean())
    ratios = np.array(means[:-1]) / np.array(means[1:])
    assert np.all((ratios > 1.7) & (ratios < 2.4)), (means, ratios)


def test_penetration_is_bounded_by_v1_dt_and_shrinks(drops: dict[float, Drop]) -> None:
    """The contact closes once the midpoint gap is <= 0: -min gap <= v1 dt, shrinking with dt."""
    v1 = np.sqrt(2.0 * GRAVITY * HEIGHTS)
    means = []
    for dt in TIME_STEPS:
        # At grid points (a ball may touch only at step midpoints: then 0).
        penetration = np.maximum(-(drops[dt].y - RADIUS).min(axis=0), 0.0)
        assert np.count_nonzero(penetration) > len(HEIGHTS) // 2
        assert np.all(penetration <= v1 * dt), (dt, (penetration / (v1 * dt)).max())
        means.append(penetration.mean())
    ratios = np.array(means[:-1]) / np.array(means[1:])
    assert np.all((ratios > 1.7) & (ratios < 2.4)), (means, ratios)


def test_comes_to_rest_at_the_zeno_time(zeno_drops: dict[float, Drop]) -> None:
    """At rest (|u| <= 1e-10, y frozen) from t_inf + O(dt) on, up to 2 t_inf: no runaway."""
    t_inf = zeno_time(ZENO_HEIGHTS, 0.8)
    means = []
    for dt in TIME_STEPS:
        run = zeno_drops[dt]
        moving = np.abs(run.v) > 1e-10
        last_moving = np.array([np.nonzero(m)[0].max() for m in moving.T])
        t_rest = (last_moving + 1) * dt
        delay = t_rest - t_inf
        # Every resolved bounce adds O(dt): measured delay is ~70 dt on average, <= 85 dt.
        assert np.all((delay > -dt) & (delay < 120.0 * dt)), (dt, delay / dt)
        means.append(delay.mean())
        for c in range(len(ZENO_HEIGHTS)):
            rest = slice(last_moving[c] + 1, None)
            assert np.ptp(run.y[rest, c]) <= 1e-12
            assert run.y[rest, c].max() <= RADIUS
            # Resting on the ground: the penetration at rest is O(dt^2) (gravity over one step).
            assert abs(run.y[-1, c] - RADIUS) <= GRAVITY * dt**2
            # Supported: one step of gravity per step, as an impulse.
            np.testing.assert_allclose(run.p_n[-10:, c], MASS * GRAVITY * dt, rtol=1e-12)
    ratios = np.array(means[:-1]) / np.array(means[1:])
    assert np.all((ratios > 1.6) & (ratios < 2.6)), (means, ratios)


def test_frictionless_contact_has_no_tangential_impulse(drops: dict[float, Drop]) -> None:
    assert np.all(drops[1e-3].p_t == 0.0)


def test_plastic_landing(make_stepper: Callable[..., MoreauJeanStepper]) -> None:
    """Eps = 0: the first impact stops the ball within a step of t1; it stays at rest."""
    for dt in TIME_STEPS:
        run = drop(make_stepper(BouncingBall, dt, restitution=0.0), ZENO_HEIGHTS, 1.0)
        t1 = first_impact(ZENO_HEIGHTS)
        v1 = np.sqrt(2.0 * GRAVITY * ZENO_HEIGHTS)
        for c in range(len(ZENO_HEIGHTS)):
            land = impact_steps(run.p_n[:, c])[0]
            assert abs((land + 0.5) * dt - t1[c]) <= dt
            after = slice(land + 1, None)
            assert np.all(run.v[after, c] == 0.0)
            assert np.ptp(run.y[after, c]) == 0.0
            assert 0.0 < RADIUS - run.y[-1, c] <= v1[c] * dt
            assert np.all(run.p_n[land + 1 :, c] > 0.0)


def test_elastic_bounces_conserve_energy(make_stepper: Callable[..., MoreauJeanStepper]) -> None:
    """Eps = 1: the grid energy is conserved to round-off, so every apex is h0 within O(dt^2)."""
    for dt in TIME_STEPS:
        run = drop(make_stepper(BouncingBall, dt, restitution=1.0), ZENO_HEIGHTS, 5.0)
        energy = 0.5 * run.v**2 + GRAVITY * (run.y - RADIUS)  # per unit mass
        expected = np.broadcast_to(GRAVITY * ZENO_HEIGHTS, energy.shape)
        np.testing.assert_allclose(energy, expected, rtol=0, atol=1e-12)
        for c, h0 in enumerate(ZENO_HEIGHTS):
            starts = impact_steps(run.p_n[:, c])
            assert len(starts) >= 5  # 5 s of bounces of period 2 t1 <= 0.95 s
            # The impact step returns the ball to where it started: up to 2 dt lost per bounce.
            lag = (starts + 0.5) * dt - impact_times(h0, 1.0, len(starts))
            assert np.all(np.abs(lag) <= (2.0 * np.arange(len(starts)) + 1.0) * dt)
            apexes = [run.y[a + 1 : b + 1, c].max() - RADIUS
                      for a, b in zip(starts[:-1], starts[1:], strict=True)]  # fmt: skip
            # The grid samples the apex parabola within dt/2 of its top.
            assert np.all(np.abs(np.array(apexes) - h0) <= 0.125 * GRAVITY * dt**2 + 1e-12)


@pytest.mark.parametrize("eps", [0.0, 0.5, 0.8])
def test_grid_energy_increase_is_at_most_second_order(
    make_stepper: Callable[..., MoreauJeanStepper], eps: float
) -> None:
    """Eps < 1: energy falls overall; single steps may gain at most g^2 dt^2 (per unit mass).

    (Steps in the Zeno phase where the ball is below ground but moving up have a closed
    contact; Newton's law turns them around and the grid energy rises by O(g^2 dt^2): see
    ``test_design_energy_never_increases``.)
    """
    for dt in TIME_STEPS:
        t_end = 1.5 * float(zeno_time(ZENO_HEIGHTS.max(), eps))
        run = drop(make_stepper(BouncingBall, dt, restitution=eps), ZENO_HEIGHTS, t_end)
        energy = 0.5 * run.v**2 + GRAVITY * (run.y - RADIUS)
        assert np.diff(energy, axis=0).max() <= GRAVITY**2 * dt**2
        assert np.all(energy[-1] < energy[0])


@pytest.mark.xfail(
    strict=True,
    reason=(
        "the midpoint scheme evaluates the contact at q_M: a ball slightly below ground and "
        "rising is reversed by the restitution law, gaining at most g^2 dt^2 per step "
        "(bounded by the test above)"
    ),
)
def test_design_energy_never_increases(make_stepper: Callable[..., MoreauJeanStepper]) -> None:
    """The textbook property "with eps <= 1 and no control the energy never increases".

    FAILS (reported): default ball, dt = 1e-3, dropped from rest at h0 = 1 m. At step 4061
    (t = 4.061 s, in the Zeno phase) the state is y - r = -2.31e-6 m, y' = +2.60e-3 m/s:
    below ground but separating. The contact is closed at the midpoint, Newton's law
    xi = u+ + eps u- >= 0 reverses it (u+ = -eps u- = -2.08e-3 m/s) and the energy
    m y'^2 / 2 + m g (y - r) rises by 1.33e-7 J. The rise is O(g^2 dt^2), see
    ``test_grid_energy_increase_is_at_most_second_order``.
    """
    stepper = make_stepper(BouncingBall, 1e-3)
    run = drop(stepper, np.array([1.0]), 5.0)
    energy = MASS * (0.5 * run.v**2 + GRAVITY * (run.y - RADIUS))
    assert np.diff(energy, axis=0).max() <= 1e-12 * energy[0, 0]
