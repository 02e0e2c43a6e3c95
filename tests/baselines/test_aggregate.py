"""Statistics over seeds (rliable): IQM, bootstrap CIs, moving success curves."""

from __future__ import annotations

import numpy as np
import pytest

from baselines.aggregate import (
    improvement_probability,
    iqm_interval,
    optimality_score,
    pairwise_win_rate,
    performance_profiles,
    sampled_curve,
    success_curve,
    training_curves,
)
from baselines.records import Estimate

pytest.importorskip("rliable", reason="rliable is in the rl extra")


def test_iqm_interval_trims_quartiles_and_brackets_the_estimate() -> None:
    values = [0.0, 0.9, 0.95, 1.0, 1.0, 1.0, 1.0, 10.0]  # IQM: mean of the middle four
    estimate = iqm_interval(values, reps=500)
    assert estimate.iqm == pytest.approx(np.mean([0.95, 1.0, 1.0, 1.0]))
    assert estimate.mean == pytest.approx(np.mean(values))
    assert estimate.n == 8 and estimate.missing == 0
    low, high = estimate.ci
    assert low <= estimate.iqm <= high
    assert iqm_interval(values, reps=0).ci is None  # no bootstrap: the estimates alone
    before = np.random.get_state()[1].copy()
    assert iqm_interval(values, reps=500) == estimate  # seeded resampling
    assert np.array_equal(np.random.get_state()[1], before)  # the global generator restored


def test_iqm_interval_drops_missing_runs_and_gives_one_run_no_interval() -> None:
    assert iqm_interval([1.5, None, float("nan")]) == Estimate(1, 2, 1.5, 1.5, None, [1.5])
    assert iqm_interval([]).iqm is None and iqm_interval([]).mean is None


def test_success_curve_is_the_moving_mean_of_finished_episodes() -> None:
    steps = np.array([10.0, 20.0, 30.0, 40.0])
    success = np.array([0.0, 1.0, 1.0, 1.0])
    curve = success_curve(steps, success, np.array([5.0, 10.0, 25.0, 40.0]), window=2)
    assert np.isnan(curve[0])
    assert curve[1:] == pytest.approx([0.0, 0.5, 1.0])


def test_sampled_curve_spans_the_run() -> None:
    steps, rates = sampled_curve(np.arange(1.0, 401.0), (np.arange(400) >= 200).astype(float),
                                 num_points=5)
    assert steps.tolist() == [1.0, 100.75, 200.5, 300.25, 400.0]
    assert rates.tolist() == pytest.approx([0.0, 0.0, 0.0, 1.0, 1.0])  # moving mean of 100


def test_training_curves_band_needs_two_runs() -> None:
    run = sampled_curve(np.arange(1.0, 201.0), (np.arange(200) > 100).astype(float))
    curves = training_curves({"one": [run], "two": [run, run]}, num_points=5, reps=100)
    assert curves["one"].ci is None and curves["one"].n == 1
    assert curves["two"].ci.shape == (2, 5)
    assert curves["two"].iqm == pytest.approx(curves["one"].iqm)
    assert curves["one"].steps == pytest.approx(np.geomspace(1.0, 200.0, 5))  # log step axis


def test_performance_profile_counts_runs_above_tau() -> None:
    taus = np.array([0.0, 0.5, 1.0])
    profiles, intervals = performance_profiles({"a": [0.2, 0.6, 1.0], "one": [0.7]}, taus,
                                               reps=100)  # fmt: skip
    assert profiles["a"] == pytest.approx([1.0, 2 / 3, 0.0])
    assert intervals["a"].shape == (2, 3)
    assert list(profiles) == ["a", "one"] and "one" not in intervals  # one run: no band
    assert profiles["one"] == pytest.approx([1.0, 1.0, 0.0])


def test_improvement_probability_is_the_pairwise_win_rate() -> None:
    # P(X > Y) over all run pairs, ties counted half (the Mann-Whitney U over n m)
    point, ci = improvement_probability([0.9, 0.8, 0.7], [0.1, 0.2], reps=200)
    assert point == 1.0 and ci == (1.0, 1.0)
    assert improvement_probability([1.0, 0.0], [0.5])[0] == 0.5
    assert improvement_probability([0.4, 0.6], [0.5, 0.6], reps=200)[0] == pytest.approx(
        (0 + 0 + 1 + 0.5) / 4)  # fmt: skip
    point, ci = improvement_probability([0.3], [0.2])
    assert point == 1.0 and ci is None  # one run each: no interval
    _, ci = improvement_probability([0.1, 0.5, 0.9], [0.2, 0.6], reps=500)
    assert ci is not None and 0.0 <= ci[0] < ci[1] <= 1.0


def test_the_win_rate_is_rliables_probability_of_improvement() -> None:
    from rliable import metrics

    rng = np.random.default_rng(3)
    for n, m in ((5, 3), (10, 10), (1, 4)):
        x = rng.integers(0, 4, (n, 1)) / 4  # ties included
        y = rng.integers(0, 4, (m, 1)) / 4
        assert pairwise_win_rate(x, y) == pytest.approx(
            metrics.probability_of_improvement(x, y), abs=1e-12)  # fmt: skip


def test_optimality_score_is_zero_without_success() -> None:
    assert optimality_score(None) == 0.0 and optimality_score(1.25) == pytest.approx(0.8)
