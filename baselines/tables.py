"""The Markdown tables of studies (pandas ``to_markdown``): the comparison and the robustness.

``comparison_table``: one row per env x objective x condition x controller with the IQM [95 % CI]
over runs (n) of each score, the nominal start, the compute per step, its real-time factor and
the training budget.
``brake_use_table``: per study with a brake, how each controller uses it (engagements per episode,
time engaged, first engagement, impulse) and the nominal episode's engaged intervals.
``improvement_table``: per study, the probability of improvement (rliable) of each trained
algorithm over every other row but the optimum, in success rate and optimality score.
``robustness_table``: per study, one row per controller and one column per condition with the
success rate (mean over runs) and, over the successes, the time or effort ratio (mean over the
runs with successes), the compute per step and its real-time factor. Both read the rows'
aggregates (``baselines.evaluation.aggregate``). The real-time factor is the mean compute per
step over the control period, the env's dt: the reference's grid step h.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

import numpy as np
import pandas as pd

from baselines.records import OPTIMAL, Episode, Estimate, Row, Run, Study
from optimal.references import load_reference


def interval_text(estimate: Estimate, percent: bool = False) -> str:
    """"IQM [low, high] (n=k)", "value (n=1, no CI)" or "-" (no run with a score)."""
    if estimate.iqm is None:
        return "-"

    def show(value: float) -> str:
        return f"{100 * value:.0f} %" if percent else f"{value:.2f}"

    missing = f", {estimate.missing} without" if estimate.missing else ""
    if estimate.ci is None:
        return f"{show(estimate.iqm)} (n={estimate.n}, no CI{missing})"
    low, high = estimate.ci
    return f"{show(estimate.iqm)} [{show(low)}, {show(high)}] (n={estimate.n}{missing})"


def budget_text(row: Row, condition: str) -> str:
    """A row's training budget and seeds, e.g. "1e+07 steps, 64 envs, seeds 0-4" ("" untrained)."""
    trainings = [run.training for run in row.at(condition) if run.training is not None]
    if not trainings:
        return ""
    seeds = sorted(t.seed for t in trainings)
    seed_text = (f"seed {seeds[0]}" if len(seeds) == 1 else
                 f"seeds {seeds[0]}-{seeds[-1]}" if seeds == list(range(seeds[0], seeds[-1] + 1))
                 else "seeds " + ",".join(map(str, seeds)))  # fmt: skip
    budget = "/".join(sorted({f"{t.num_timesteps:.2g}" for t in trainings}))
    return f"{budget} steps, {trainings[0].num_envs} envs, {seed_text}"


def _nominal_text(row: Row, condition: str) -> str:
    nominals = [run.nominal for run in row.at(condition) if run.nominal is not None]
    if not nominals:
        return "-"
    if row.trained:
        return f"{sum(e.is_success for e in nominals)} of {len(nominals)} runs succeed"
    (nominal,) = nominals
    return (f"success, {nominal.elapsed_time:.2f} s, effort {nominal.effort:.3g}"
            if nominal.is_success else "fails")  # fmt: skip


def _mean_compute(runs: Sequence[Run]) -> float | None:
    """The mean wall time [s] of one policy call over the runs' perturbed episodes, if known."""
    times = [run.scores.compute_per_step for run in runs]
    return None if not times or any(t is None for t in times) else float(np.mean(times))


def _compute_text(runs: Sequence[Run]) -> str:
    """``_mean_compute`` as text."""
    seconds = _mean_compute(runs)
    if seconds is None:
        return "-"
    return f"{1e3 * seconds:.3g} ms" if seconds < 1.0 else f"{seconds:.2f} s"


@cache
def control_period(reference: str) -> float:
    """The control period [s] of the studies of ``reference``: its grid step h, the env's dt."""
    return load_reference(reference).time_step


def _real_time_text(runs: Sequence[Run], period: float) -> str:
    """``_mean_compute`` over the control period ``period`` [s], as text."""
    seconds = _mean_compute(runs)
    return "-" if seconds is None else f"{seconds / period:.2g}"


def comparison_table(studies: Sequence[Study]) -> str:
    """One row per env x objective x condition x controller: IQM [95 % CI] over runs of each score.

    A trained algorithm's runs are its training seeds; an untrained controller is one run (its
    cells show the value alone). Needs each row's aggregates (``evaluation.aggregate``).
    """
    records = []
    for study in studies:
        for condition in study.conditions:
            for row in study.rows:
                estimates = row.aggregate(condition.label)
                if estimates is None:
                    continue
                scores = (estimates.success_rate, estimates.time_ratio, estimates.effort_ratio)
                runs = len(row.at(condition.label))
                if row.trained:
                    count = f"{runs} seed{'s' * (runs != 1)} x {study.num_starts} starts"
                    cells = [interval_text(scores[0], percent=True),
                             *(interval_text(e) for e in scores[1:])]
                else:
                    count = f"controller, {study.num_starts} starts"
                    cells = [f"{100 * (scores[0].iqm or 0.0):.0f} %",
                             *(f"{e.iqm:.2f}" if e.iqm is not None else "-" for e in scores[1:])]
                label = condition.label
                records.append([study.env_id.split("/")[-1], study.objective,
                                f"{condition.scale:g}", row.label, count, *cells,
                                _nominal_text(row, label), _compute_text(row.at(label)),
                                _real_time_text(row.at(label), control_period(study.reference)),
                                budget_text(row, label)])  # fmt: skip
    columns = ["env", "objective", "start scale", "controller", "runs",
               "success (perturbed starts), IQM [95 % CI]", "time / optimal",
               "effort / optimal", "nominal start", "compute / step", "real-time factor",
               "training budget"]
    return pd.DataFrame(records, columns=columns).to_markdown(index=False)


def engaged_intervals(episode: Episode | None) -> list[tuple[float, float]]:
    """The (start, end) times [s] of the brake's engaged intervals in a kept trajectory."""
    if episode is None or episode.trajectory is None or not episode.trajectory.schedule:
        return []
    time = np.asarray(episode.trajectory.time)
    on = np.concatenate(([False], np.asarray(episode.trajectory.schedule) > 0.5, [False]))
    edges = np.flatnonzero(np.diff(on.astype(int)))
    return [(float(time[a]), float(time[b])) for a, b in edges.reshape(-1, 2)]


def _intervals_text(intervals: list[tuple[float, float]], shown: int = 4) -> str:
    """"2.02-2.55, 4.15-4.19", the first ``shown`` intervals and "+k more" ("-": none)."""
    text = ", ".join(f"{a:.2f}-{b:.2f}" for a, b in intervals[:shown])
    more = len(intervals) - shown
    return (text + (f", +{more} more" if more > 0 else "")) or "-"


def brake_use_table(studies: Sequence[Study]) -> str:
    """One row per study x condition x controller: how the brake is used (``BrakeUse``).

    Over the row's perturbed episodes (all runs): engagements per episode (mean, range), time
    engaged [s], the median first engagement [s] and the impulse [N m s] (means); the engaged
    intervals of the first run's nominal episode. Studies without brake records are left out.
    """
    records = []
    for study in studies:
        for condition in study.conditions:
            for row in study.rows:
                runs = row.at(condition.label)
                uses = [e.brake_use for run in runs for e in run.episodes
                        if e.brake_use is not None]  # fmt: skip
                if not uses:
                    continue
                counts = [use.engagements for use in uses]
                firsts = [use.first_engagement for use in uses if use.first_engagement is not None]
                nominal = engaged_intervals(runs[0].nominal) if runs else []
                records.append([
                    study.env_id.split("/")[-1], f"{condition.scale:g}", row.label, len(runs),
                    f"{np.mean(counts):.1f} ({min(counts)}-{max(counts)})",
                    f"{np.mean([use.engaged_time for use in uses]):.2f}",
                    f"{np.median(firsts):.2f}" if firsts else "never",
                    f"{np.mean([use.impulse for use in uses]):.3g}",
                    _intervals_text(nominal)])  # fmt: skip
    columns = ["env", "start scale", "controller", "runs", "engagements / episode (range)",
               "engaged [s]", "first engagement [s], median", "impulse [N m s]",
               "engaged (nominal start, first run) [s]"]
    return pd.DataFrame(records, columns=columns).to_markdown(index=False) if records else ""


def _probability_text(point: float, ci: tuple[float, float] | None) -> str:
    return f"{point:.2f}" + (f" [{ci[0]:.2f}, {ci[1]:.2f}]" if ci is not None else "")


def improvement_table(studies: Sequence[Study], reps: int | None = None) -> str:
    """P(X > Y) [95 % CI] for each trained row X against each untrained and later trained row Y.

    Per study and condition, over runs: in success rate, and in optimality score (optimum
    over the run's mean time or effort on its successes, 0 without success;
    ``aggregate.optimality_score``). The optimal reference's row is not a Y (it is the unit).
    ``reps``: bootstrap replications (default ``aggregate.BOOTSTRAP_REPS``).
    """
    from baselines.aggregate import BOOTSTRAP_REPS, improvement_probability, optimality_score

    reps = BOOTSTRAP_REPS if reps is None else reps
    records = []
    for study in studies:
        ratio = "effort_ratio" if study.objective == "effort" else "time_ratio"
        for condition in study.conditions:
            rows = [row for row in study.rows if row.at(condition.label) and row.label != OPTIMAL]
            scores = {row.label: (
                [run.scores.success_rate for run in row.at(condition.label)],
                [optimality_score(getattr(run.scores, ratio)) for run in row.at(condition.label)])
                for row in rows}  # fmt: skip
            for i, x in enumerate(rows):
                others = [y for j, y in enumerate(rows) if j > i or not y.trained]
                for y in others if x.trained else []:
                    cells = [_probability_text(*improvement_probability(a, b, reps)) for a, b
                             in zip(scores[x.label], scores[y.label], strict=True)]  # fmt: skip
                    records.append([study.env_id.split("/")[-1], study.objective,
                                    f"{condition.scale:g}", x.label, y.label, *cells])
    columns = ["env", "objective", "start scale", "X", "Y", "P(X > Y), success [95 % CI]",
               "P(X > Y), optimality [95 % CI]"]
    return pd.DataFrame(records, columns=columns).to_markdown(index=False) if records else ""


def comparison_report(studies: Sequence[Study], reps: int | None = None) -> str:
    """The comparison's Markdown file (``compare.md``): the tables of ``studies``.

    ``comparison_table``, then the probability of improvement and the brake use where there are
    any (``reps``: the bootstrap replications of ``improvement_table``).
    """
    sections = [comparison_table(studies)]
    for title, text in (("Probability of improvement", improvement_table(studies, reps)),
                        ("Brake use", brake_use_table(studies))):
        sections += [title, text] if text else []
    return "\n\n".join(sections) + "\n"


def robustness_table(studies: Sequence[Study]) -> str:
    """Per study a title line and a table: success (ratio over the successes) per condition.

    Success is the mean over the row's runs, the ratio the mean over its runs with successes
    (each row's aggregates: ``evaluation.aggregate``); the last two columns are the mean wall
    time of one policy call over all of the row's runs and its ratio to the control period.
    """
    parts = []
    for study in studies:
        ratio = "effort" if study.objective == "effort" else "time"
        records = []
        for row in study.rows:
            cells, runs = [], 0
            for condition in study.conditions:
                estimates = row.aggregate(condition.label)
                if estimates is None:
                    cells.append("-")
                    continue
                mean = getattr(estimates, f"{ratio}_ratio").mean
                runs = max(runs, estimates.success_rate.n)
                cells.append(f"{estimates.success_rate.mean or 0.0:.0%}"
                             + ("" if mean is None else f" ({mean:.2f})"))
            played = [run for c in study.conditions for run in row.at(c.label)]
            records.append([row.label, runs, *cells, _compute_text(played),
                            _real_time_text(played, control_period(study.reference))])
        table = pd.DataFrame(records, columns=["controller", "runs",
                                               *(c.label for c in study.conditions),
                                               "compute / step", "real-time factor"])
        parts.append(f"{study.env_id} {study.objective} ({study.num_starts} starts per run; "
                     f"success, {ratio}/optimal over the successes)\n\n"
                     + table.to_markdown(index=False))
    return "\n\n".join(parts)


__all__ = ["brake_use_table", "budget_text", "comparison_report", "comparison_table",
           "engaged_intervals", "improvement_table", "interval_text", "robustness_table"]
