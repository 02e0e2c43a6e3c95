"""Statistics over training seeds with rliable: IQM, 95 % bootstrap CIs, profiles, curves.

The unit is the run (one training seed), as in Agarwal et al., "Deep RL at the Edge of the
Statistical Precipice" (NeurIPS 2021), whose library ``rliable`` computes everything here: a
run's score on one env x task (its success rate over the perturbed starts, or its time or
effort ratio to the optimum) is one sample; the interquartile mean (IQM,
``rliable.metrics.aggregate_iqm``) over runs is the point estimate and the 95 % stratified
bootstrap (``rliable.library.get_interval_estimates``, percentile method, over runs) its
confidence interval. One run gives no interval (``ci`` None: "n=1, no CI"). Performance
profiles (``rliable.library.create_performance_profile``): the fraction of runs whose score
exceeds each threshold tau, with bootstrap bands. Probability of improvement
(``rliable.metrics.probability_of_improvement``'s statistic, ``pairwise_win_rate``): P(X > Y)
of a run of X against a run of Y (the Mann-Whitney U over n x m pairs, ties counted half), with
an independent stratified-bootstrap CI. Training curves: each run's success rate
(moving mean over its last 100 training episodes) on a common grid of environment steps,
IQM and CI per grid point.

Bootstrap replications: ``BOOTSTRAP_REPS`` = 2000 (rliable's default 50000 takes ~30 s per
estimate on this CPU; the percentile bounds of 2000 differ in the second digit at most).
The resampling is seeded (``seed``), so a table is reproducible: rliable 1.2 draws its
resampling indices from NumPy's global generator (``np.random.choice`` in
``StratifiedBootstrap.update_indices``) whatever ``random_state`` it is given, so each estimate
seeds that generator and restores its previous state afterwards (``_seeded``).
"""

from __future__ import annotations

import contextlib
import functools
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from baselines.records import Estimate

BOOTSTRAP_REPS = 2000
"""Bootstrap replications per interval estimate."""
CONFIDENCE = 0.95
"""Coverage of the intervals."""


@contextlib.contextmanager
def _seeded(seed: int) -> Iterator[None]:
    """Seed NumPy's global generator (rliable resamples with it), restore it afterwards.

    Also silences arch's FutureWarning about ``random_state``.
    """
    state = np.random.get_state()
    np.random.seed(seed)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            yield
    finally:
        np.random.set_state(state)


def _iqm(scores: np.ndarray) -> np.ndarray:
    from rliable import metrics

    return np.array([metrics.aggregate_iqm(scores)])


def iqm_interval(values: Sequence[float | None], reps: int = BOOTSTRAP_REPS, seed: int = 0
                 ) -> Estimate:  # fmt: skip
    """The IQM over runs and its 95 % stratified-bootstrap CI.

    Args:
        values: one score per run; None or NaN (e.g. a ratio of a run without success) is left
            out and counted in ``missing``.
        reps: bootstrap replications. seed: the resampling's seed.

    Returns:
        The ``Estimate``: ``mean`` and ``iqm`` None without a run, ``ci`` None with fewer
        than 2 or ``reps`` 0.
    """
    from rliable import library

    scores = [float(v) for v in values if v is not None and np.isfinite(v)]
    iqm, ci = None, None
    if scores:
        matrix = np.asarray(scores)[:, None]  # (runs, 1 task)
        iqm = float(_iqm(matrix)[0])
    if len(scores) >= 2 and reps > 0:
        with _seeded(seed):
            _, intervals = library.get_interval_estimates(
                {"runs": matrix}, _iqm, reps=reps, confidence_interval_size=CONFIDENCE)
        ci = (float(intervals["runs"][0, 0]), float(intervals["runs"][1, 0]))
    mean = float(np.mean(scores)) if scores else None
    return Estimate(len(scores), len(values) - len(scores), mean, iqm, ci, scores)


def performance_profiles(scores: Mapping[str, Sequence[float]], taus: np.ndarray,
                         reps: int = BOOTSTRAP_REPS, seed: int = 0
                         ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:  # fmt: skip
    """The score distributions of rliable: the fraction of runs with score > tau, with CIs.

    Labels with one run get the profile alone (no bootstrap: it would only repeat the run).

    Args:
        scores: label -> one score per run. taus: (T,) thresholds.
        reps: bootstrap replications. seed: the resampling's seed.

    Returns:
        (profiles: label -> (T,), intervals: label -> (2, T) lower and upper bounds, for the
        labels with two runs or more).
    """
    from rliable import library

    matrices = {label: np.asarray(values, dtype=float)[:, None]
                for label, values in scores.items() if len(values)}  # fmt: skip
    several = {label: m for label, m in matrices.items() if len(m) >= 2}
    profiles: dict[str, np.ndarray] = {}
    intervals: dict[str, np.ndarray] = {}
    if several:
        with _seeded(seed):
            profiles, intervals = library.create_performance_profile(
                several, taus, reps=reps, confidence_interval_size=CONFIDENCE)
    singles = {label: np.mean(m[:, :, None] > taus, axis=(0, 1)) for label, m in matrices.items()
               if label not in several}  # fmt: skip
    return {label: {**profiles, **singles}[label] for label in matrices}, dict(intervals)


def optimality_score(ratio: float | None) -> float:
    """Optimum / the run's mean time or effort over its successes (``ratio``); 0 if none."""
    return 0.0 if ratio is None else 1.0 / ratio


def pairwise_win_rate(scores_x: np.ndarray, scores_y: np.ndarray) -> float:
    """P(X > Y) on one task: the fraction of run pairs where X scores higher, ties half.

    ``scores_x`` (n, 1), ``scores_y`` (m, 1). The statistic of
    ``rliable.metrics.probability_of_improvement`` (the Mann-Whitney U over n m) in numpy:
    SciPy's test per bootstrap replication made a table of a few pairs take minutes.
    """
    x, y = scores_x[:, 0][:, None], scores_y[:, 0][None, :]
    return float(np.count_nonzero(x > y) + 0.5 * np.count_nonzero(x == y)) / (x.size * y.size)


def improvement_probability(x: Sequence[float], y: Sequence[float], reps: int = BOOTSTRAP_REPS,
                            seed: int = 0) -> tuple[float, tuple[float, float] | None]:
    """P(X > Y) over runs (one score per run of X and of Y) and its 95 % CI.

    The CI (rliable's independent stratified bootstrap of both samples) is None when neither
    has two runs or ``reps`` is 0. Results are memoized per (x, y, reps, seed): a comparison
    report asks for the same pairs in its summary and in each study's table.
    """
    return _improvement_probability(tuple(map(float, x)), tuple(map(float, y)), reps, seed)


@functools.lru_cache(maxsize=4096)
def _improvement_probability(x: tuple[float, ...], y: tuple[float, ...], reps: int,
                             seed: int) -> tuple[float, tuple[float, float] | None]:
    """``improvement_probability`` on hashable samples."""
    from rliable import library

    scores = (np.asarray(x, dtype=float)[:, None], np.asarray(y, dtype=float)[:, None])
    point = pairwise_win_rate(*scores)
    if max(len(x), len(y)) < 2 or reps <= 0:
        return point, None
    with _seeded(seed):
        _, intervals = library.get_interval_estimates(
            {"pair": scores}, pairwise_win_rate, reps=reps,
            confidence_interval_size=CONFIDENCE)  # fmt: skip
    low, high = np.ravel(intervals["pair"])
    return point, (float(low), float(high))


CURVE_POINTS = 200
"""Points of a run's compact training curve (``sampled_curve``, ``STEM_curve.csv``)."""


def success_curve(steps: np.ndarray, success: np.ndarray, grid: np.ndarray,
                  window: int = 100) -> np.ndarray:  # fmt: skip
    """One run's success rate (moving mean over ``window`` episodes) at ``grid`` steps.

    Args:
        steps: (E,) environment steps at which each training episode ended (ascending).
        success: (E,) 0/1 per episode. grid: (G,) steps to sample at.

    Returns:
        (G,) the moving mean of the episodes ended by each grid step (NaN before the first).
    """
    if len(steps) == 0:
        return np.full(len(grid), np.nan)
    sums = np.cumsum(np.asarray(success, dtype=float))
    index = np.searchsorted(steps, grid, side="right") - 1  # last episode ended by grid step
    start = np.maximum(index - window, -1)
    previous = np.where(start >= 0, sums[np.maximum(start, 0)], 0.0)
    count = index - start
    with np.errstate(invalid="ignore", divide="ignore"):
        curve = (sums[np.maximum(index, 0)] - previous) / count
    return np.where(index >= 0, curve, np.nan)


def sampled_curve(steps: np.ndarray, success: np.ndarray, num_points: int = CURVE_POINTS,
                  window: int = 100) -> tuple[np.ndarray, np.ndarray]:
    """One run's ``success_curve`` on ``num_points`` steps from its first to its last episode.

    Returns:
        (steps (P,), success rate (P,)): the compact curve ``STEM_curve.csv`` keeps.
    """
    steps = np.asarray(steps, dtype=float)
    if len(steps) == 0:
        return np.zeros(0), np.zeros(0)
    grid = np.linspace(steps[0], steps[-1], num_points)
    return grid, success_curve(steps, success, grid, window)


@dataclass(frozen=True)
class Curve:
    """IQM over runs of a training curve: steps (G,), iqm (G,), ci (2, G) or None, n runs."""

    steps: np.ndarray
    iqm: np.ndarray
    ci: np.ndarray | None
    n: int


def training_curves(runs: Mapping[str, Sequence[tuple[np.ndarray, np.ndarray]]],
                    num_points: int = 40, reps: int = BOOTSTRAP_REPS, seed: int = 0
                    ) -> dict[str, Curve]:  # fmt: skip
    """IQM and 95 % CI over runs of the training success rate, per label.

    Args:
        runs: label -> one curve (steps (P,), success rate (P,)) per run (``sampled_curve``,
            ascending steps), interpolated linearly onto the common grid.
        num_points: grid points, evenly spaced in log(steps), from the latest first step to
            the shortest run's last step.
        reps: bootstrap replications. seed: the resampling's seed.

    Returns:
        label -> its ``Curve`` (``ci`` None for one run).
    """
    from rliable import library

    curves: dict[str, Curve] = {}
    for label, logs in runs.items():
        logs = [(np.asarray(s, float), np.asarray(r, float)) for s, r in logs if len(s)]
        if not logs:
            continue
        end = min(float(steps[-1]) for steps, _ in logs)
        grid = np.geomspace(max(1.0, max(float(steps[0]) for steps, _ in logs)), end, num_points)
        matrix = np.stack([np.interp(grid, s, r) for s, r in logs])[:, None, :]  # (R, 1, G)

        def per_point(scores: np.ndarray) -> np.ndarray:
            from rliable import metrics

            return np.array([metrics.aggregate_iqm(scores[..., g])
                             for g in range(scores.shape[-1])])  # fmt: skip

        point = per_point(matrix)
        interval = None
        if len(logs) >= 2:
            with _seeded(seed):
                _, intervals = library.get_interval_estimates(
                    {label: matrix}, per_point, reps=reps, confidence_interval_size=CONFIDENCE)
            interval = intervals[label]
        curves[label] = Curve(grid, point, interval, len(logs))
    return curves


__all__ = [
    "BOOTSTRAP_REPS", "CONFIDENCE", "CURVE_POINTS", "Curve", "improvement_probability",
    "iqm_interval", "optimality_score", "pairwise_win_rate", "performance_profiles",
    "sampled_curve", "success_curve", "training_curves",
]
