"""Typed records of an evaluation study (episode, run, controller row, study) and their JSON.

A study plays controllers in one env x objective under conditions: a start-perturbation scale
(the env's ``reset_noise_scale``) and optionally a model mismatch the controllers do not know.
A comparison is a study at the nominal conditions. Nesting: ``Study`` -> ``Row`` (one
controller: an untrained one, or an algorithm over its training seeds) -> ``Run`` (one training
seed, or the controller, under one condition) -> ``Episode``. ``read_study`` and ``write_study``
convert to and from JSON (pydantic validates what is read).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np

DEFAULT_SCALE = 0.01
"""The envs' default start perturbation half-width [rad, rad/s, m, m/s]."""

OPTIMAL = "optimal (open loop)"
"""The label of the optimal reference's row (drawn in black in the plots)."""


@dataclass(frozen=True)
class Condition:
    """What a run is played under.

    Attributes:
        scale: start perturbation half-width [rad, rad/s, m, m/s] (uniform in [-scale, scale]).
        mismatch: the label of a model mismatch in the env only (None: the nominal model).
    """

    scale: float = DEFAULT_SCALE
    mismatch: str | None = None

    @property
    def label(self) -> str:
        """"perturbation 0.01", or the mismatch's label."""
        return self.mismatch if self.mismatch is not None else f"perturbation {self.scale:g}"


@dataclass(frozen=True)
class Trajectory:
    """The states of one episode: time (N + 1,) [s], q (N + 1, n), schedule (N,) per step.

    ``schedule`` is the brake engaged (0/1) or the robot's slip mode (2/3/5 DOF).
    """

    time: list[float]
    q: list[list[float]]
    schedule: list[float]


@dataclass(frozen=True)
class BrakeUse:
    """How one episode used the manipulator's brake.

    Attributes:
        engagements: env steps with the brake engaged after a step with it released (the first
            step counts when it starts engaged). engaged_time: time engaged [s].
        first_engagement: start of the first engaged step [s] (None: never engaged).
        impulse: sum of the brake impulse magnitudes |P_B| over the episode [N m s].
    """

    engagements: int
    engaged_time: float
    first_engagement: float | None
    impulse: float

    @classmethod
    def of(cls, engaged: Sequence[float], impulses: Sequence[float], dt: float) -> BrakeUse:
        """From an episode's per-step ``info["brake_engaged"]`` (0/1), ``info["brake_impulse"]``.

        ``impulses`` in [N m s]; ``dt`` is the env step [s].
        """
        on = np.asarray(engaged, dtype=float) > 0.5
        starts = np.flatnonzero(on & ~np.concatenate(([False], on[:-1])))
        return cls(engagements=len(starts), engaged_time=float(on.sum() * dt),
                   first_engagement=float(starts[0] * dt) if len(starts) else None,
                   impulse=float(np.abs(np.asarray(impulses, dtype=float)).sum()))  # fmt: skip


@dataclass(frozen=True)
class Episode:
    """One episode from ``reset(seed=seed)``.

    Attributes:
        seed: the reset seed. is_success: ended at the goal. elapsed_time: simulated time at
        the end [s]. effort: integral of sum(tau^2) [N^2 m^2 s]. solver_failures: steps whose
        contact solve did not converge. compute_per_step: mean wall time of one policy call
        [s] (an MPC's re-solve, a network's forward pass). episode_return: sum of rewards.
        num_steps: env steps. trajectory: kept for nominal episodes and plotted ones.
        brake_use: how it used the brake (None: an env without one).
    """

    seed: int
    is_success: bool
    elapsed_time: float
    effort: float
    solver_failures: int
    compute_per_step: float
    episode_return: float | None = None
    num_steps: int | None = None
    trajectory: Trajectory | None = None
    brake_use: BrakeUse | None = None


@dataclass(frozen=True)
class Scores:
    """A run's scores over its perturbed episodes.

    Attributes:
        episodes: how many. success_rate: fraction at the goal. time_ratio, effort_ratio: mean
            time [s] and effort over the successes divided by the optimum's (None: no success).
        time_ratio_median: the median's ratio (the last five are None in a run recorded
            without them).
        mean_time, mean_effort: over the successes [s], [N^2 m^2 s].
        solver_failures: summed. compute_per_step: mean over the episodes [s].
    """

    episodes: int
    success_rate: float
    time_ratio: float | None
    effort_ratio: float | None
    time_ratio_median: float | None = None
    mean_time: float | None = None
    mean_effort: float | None = None
    solver_failures: int | None = None
    compute_per_step: float | None = None

    @classmethod
    def of(cls, episodes: Sequence[Episode], optimal_time: float, optimal_effort: float
           ) -> Scores:  # fmt: skip
        """Success rate and, over the successes, time and effort as ratios to the optimum."""
        wins = [e for e in episodes if e.is_success]
        times = np.array([e.elapsed_time for e in wins])
        efforts = np.array([e.effort for e in wins])
        return cls(
            episodes=len(episodes),
            success_rate=len(wins) / len(episodes) if episodes else 0.0,
            time_ratio=float(np.mean(times) / optimal_time) if wins else None,
            effort_ratio=float(np.mean(efforts) / optimal_effort) if wins else None,
            time_ratio_median=float(np.median(times) / optimal_time) if wins else None,
            mean_time=float(np.mean(times)) if wins else None,
            mean_effort=float(np.mean(efforts)) if wins else None,
            solver_failures=int(sum(e.solver_failures for e in episodes)),
            compute_per_step=float(np.mean([e.compute_per_step for e in episodes]))
            if episodes else 0.0,
        )  # fmt: skip


@dataclass(frozen=True)
class Training:
    """Where a trained run's policy comes from (its ``STEM.json``, ``baselines.train``).

    Attributes:
        stem: the policy's file stem. seed: the training seed. commit: the git commit it
        was trained at. num_timesteps: environment steps trained. num_envs: batched copies.
    """

    stem: str
    seed: int
    commit: str | None
    num_timesteps: int
    num_envs: int


@dataclass(frozen=True)
class Run:
    """One run: a controller (trained: one training seed) under one condition.

    Attributes:
        condition: what it was played under. scores: over ``episodes``. episodes: the
        perturbed starts (empty in a run recorded by its scores alone). nominal: the episode
        from the unperturbed start, when played. training: the trained policy (None:
        untrained controller). commit: the git commit the run was evaluated at.
    """

    condition: Condition
    scores: Scores
    episodes: list[Episode] = field(default_factory=list)
    nominal: Episode | None = None
    training: Training | None = None
    commit: str | None = None

    @property
    def seed(self) -> int | None:
        """The training seed (None for an untrained controller)."""
        return None if self.training is None else self.training.seed


@dataclass(frozen=True)
class Estimate:
    """One score aggregated over a row's runs (``baselines.aggregate.iqm_interval``).

    Attributes:
        n: runs with a score. missing: runs without (no success: no ratio). mean: their mean
        (None: no run). iqm: the interquartile mean (None: no run, or a study recorded by its
        means alone). ci: the IQM's 95 % stratified-bootstrap interval (None: fewer than 2
        runs, or no bootstrap). values: the scores (empty in a study recorded by its means).
    """

    n: int
    missing: int
    mean: float | None
    iqm: float | None
    ci: tuple[float, float] | None
    values: list[float]


@dataclass(frozen=True)
class Aggregate:
    """A row's ``Estimate`` of each score over its runs under one condition.

    The tables and plots read these; a row may hold an aggregate for a condition whose runs
    it does not keep (a study recorded by its aggregates alone).
    """

    condition: str
    success_rate: Estimate
    time_ratio: Estimate
    effort_ratio: Estimate


@dataclass(frozen=True)
class Row:
    """One controller of a study: its runs (per condition and training seed) and aggregates.

    Attributes:
        label: the controller's name in tables. trained: an algorithm over training seeds.
        runs: by condition, then training seed. aggregates: one per condition played.
    """

    label: str
    trained: bool
    runs: list[Run]
    aggregates: list[Aggregate] = field(default_factory=list)

    def at(self, condition: str) -> list[Run]:
        """The runs under the condition labelled ``condition`` (by training seed)."""
        return [run for run in self.runs if run.condition.label == condition]

    def aggregate(self, condition: str) -> Aggregate | None:
        """The aggregate under ``condition`` (None: not computed)."""
        return next((a for a in self.aggregates if a.condition == condition), None)


@dataclass(frozen=True)
class Study:
    """Controllers of one env x objective played from ``num_starts`` starts under each condition.

    Attributes:
        env_id, objective: what is played. reference: the optimal reference's name.
        optimal_time [s], optimal_effort [N^2 m^2 s]: the optimum's. num_starts: perturbed
        starts per run (reset seeds 0 ... num_starts - 1). conditions: in table order.
        rows: one per controller.
    """

    env_id: str
    objective: str
    reference: str
    optimal_time: float
    optimal_effort: float
    num_starts: int
    conditions: list[Condition]
    rows: list[Row]

    @property
    def name(self) -> str:
        """The file stem part, e.g. ``DiffDriveRobot-v0_effort``."""
        return f"{self.env_id.split('/')[-1]}_{self.objective}"

    def row(self, label: str) -> Row:
        """The row labelled ``label`` (KeyError naming the labels if none)."""
        for row in self.rows:
            if row.label == label:
                return row
        raise KeyError(f"no row {label!r}; rows: {[r.label for r in self.rows]}")



R = TypeVar("R")


def _adapter(kind: type) -> object:
    from pydantic import TypeAdapter

    return TypeAdapter(kind)


def to_json(record: object) -> object:
    """``record`` (any record of this module) as plain JSON data."""
    return _adapter(type(record)).dump_python(record, mode="json")  # type: ignore[attr-defined]


def from_json(kind: type[R], data: object) -> R:
    """A ``kind`` record from JSON data; pydantic's ``ValidationError`` names a bad field."""
    return _adapter(kind).validate_python(data)  # type: ignore[attr-defined, no-any-return]


def read_study(path: Path) -> Study:
    """The ``Study`` in the JSON file ``path``."""
    return from_json(Study, json.loads(Path(path).read_text()))


def write_study(study: Study, path: Path) -> Path:
    """Write ``study`` as JSON to ``path``; returns ``path``."""
    Path(path).write_text(json.dumps(to_json(study), indent=1) + "\n")
    return Path(path)


__all__ = [
    "DEFAULT_SCALE", "OPTIMAL", "Aggregate", "BrakeUse", "Condition", "Episode", "Estimate", "Row",
    "Run", "Scores", "Study", "Training", "Trajectory", "from_json", "read_study", "to_json",
    "write_study",
]
