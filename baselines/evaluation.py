"""The evaluation framework: play controllers under conditions into a ``Study``, merge studies.

``evaluate(env_id, objective, conditions)`` plays every controller row of (env id, objective): the
untrained controllers (``CONTROLLER_FACTORIES``: the optimal reference played open loop through the
same env id with one env step per interval of the transcription, and the heuristic floors of
``baselines.heuristics``; an MPC joins by adding a factory) and every trained policy in
``trained_dir`` (``STEM.zip`` + ``STEM.json``, one per training seed, grouped by algorithm). Each
run is played deterministically from ``reset(seed=s)``, s = 0 ... num_starts - 1, under each
``Condition``: the start perturbation scale (``reset_noise_scale``, 0.01 rad, rad/s, m, m/s by
default) and optionally a model mismatch (``MISMATCHES``) in the env only. With ``nominal=True``
each run also plays the unperturbed start (seed 0) and keeps trajectories for the plots. A
comparison is the study at the default scale (``baselines.cli``'s ``compare``); the robustness
study adds larger scales and the mismatches (``baselines.robustness``). Every finished episode can
be appended to a JSON-lines log; ``resume`` reads it back instead of playing again.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import os
import time
import warnings
from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

from baselines.hyperparameters import (
    DIFF_DRIVE,
    DIFF_DRIVE_EFFORT_V1,
    DIFF_DRIVE_V1,
    MANIPULATOR,
    MANIPULATOR_V1,
)
from baselines.records import (
    OPTIMAL,
    Aggregate,
    BrakeUse,
    Condition,
    Episode,
    Row,
    Run,
    Scores,
    Study,
    Training,
)
from baselines.records import Trajectory as TrajectoryRecord
from baselines.time_input import counting_policy
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulatorParameters
from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters
from mdi_envs.provenance import git_commit
from mdi_envs.rollout import Policy, open_loop_policy, rollout
from optimal.references import Reference, load_reference
from optimal.replay import env_actions, env_options

TRAINED_DIR = Path(__file__).parent / "trained"
"""Where the shipped policies live: ``STEM.zip`` + ``STEM.json`` (see ``baselines.train``)."""

DISTILLED_DIR = Path(__file__).parent / "distilled"
"""Where the shipped distilled policies live (``baselines.distill``), in the same format."""

REFERENCE_NAMES = {
    (MANIPULATOR, "time"): "manipulator_time",
    (DIFF_DRIVE, "time"): "diff_drive_time",
    (DIFF_DRIVE, "effort"): "diff_drive_effort",
    (MANIPULATOR_V1, "time"): "manipulator_time",
    (DIFF_DRIVE_V1, "time"): "diff_drive_time",
    (DIFF_DRIVE_EFFORT_V1, "effort"): "diff_drive_effort",
}
"""(env id, objective) -> the optimal reference it is measured against (v0 ids take the
objective as a kwarg, v1 ids have one objective each)."""

OBJECTIVES = {env_id: tuple(o for e, o in REFERENCE_NAMES if e == env_id)
              for env_id, _ in REFERENCE_NAMES}
"""The objectives of each mission environment."""

SCHEDULE_KEYS = {env_id: "brake_engaged" if "Manipulator" in env_id else "slip_mode"
                 for env_id in OBJECTIVES}
"""The per-step ``info`` entry kept as a schedule: brake engaged (0/1) or slip mode (2/3/5)."""

SCALES = (0.01, 0.03, 0.1, 0.3)
"""Start perturbation half-widths [rad, rad/s, m, m/s] of the robustness study."""

SCORES = ("success_rate", "time_ratio", "effort_ratio")
"""The per-run scores aggregated over runs."""


def _manipulator(factor: float) -> BlockableManipulatorParameters:
    nominal = BlockableManipulatorParameters()
    return dataclasses.replace(nominal, link1_mass=factor * nominal.link1_mass,
                               link2_mass=factor * nominal.link2_mass)


def _robot(mass: float = 1.0, friction: float = 1.0) -> DiffDriveParameters:
    nominal = DiffDriveParameters()
    return dataclasses.replace(nominal, mass=mass * nominal.mass,
                               wheel_friction=friction * nominal.wheel_friction,
                               stick_friction=friction * nominal.stick_friction)


_MANIPULATOR_MISMATCHES: dict[str, Callable[[], Any]] = {
    "link masses +10 %": lambda: _manipulator(1.1),
    "link masses -10 %": lambda: _manipulator(0.9)}
_ROBOT_MISMATCHES: dict[str, Callable[[], Any]] = {
    "mass +10 %": lambda: _robot(mass=1.1),
    "mass -10 %": lambda: _robot(mass=0.9),
    "friction +20 %": lambda: _robot(friction=1.2),
    "friction -20 %": lambda: _robot(friction=0.8)}
MISMATCHES: dict[str, dict[str, Callable[[], Any]]] = {
    env_id: _MANIPULATOR_MISMATCHES if "Manipulator" in env_id else _ROBOT_MISMATCHES
    for env_id in OBJECTIVES}
"""Env id -> {label: parameters factory} of its model mismatches (the env's model only). Neither
mission env has a restitution coefficient (the brake and the wheels have no impacts)."""


@dataclasses.dataclass(frozen=True)
class Controller:
    """One run of a row: a policy and the env configuration it is played in.

    Attributes:
        label: its row in tables and plots.
        make_policy: called once per episode with a ``gym.make(env_id, **env_kwargs)`` of the
            played configuration (a separate instance, e.g. to read the model and ``dt``);
            returns the policy ``obs -> action`` for that episode.
        env_kwargs: the ``gym.make`` arguments it is played with (the study sets
            ``reset_noise_scale`` and, under a mismatch, ``parameters``).
        training: the trained policy it plays (None: an untrained controller).
    """

    label: str
    make_policy: Callable[[gym.Env[Any, Any]], Policy]
    env_kwargs: dict[str, Any] = dataclasses.field(default_factory=dict)
    training: Training | None = None


ControllerFactory = Callable[[str, str], "Controller | None"]
"""(env id, objective) -> a controller, or None where it does not apply."""

CONTROLLER_FACTORIES: list[str] = ["baselines.evaluation:optimal_controller",
                                   "baselines.heuristics:heuristic_controller",
                                   "baselines.model_based:lqr_controller"]
"""The untrained controller rows, as "module:function" of a ``ControllerFactory`` (imported on
use). ``register_controller`` adds one; every study plays them in this order."""


def register_controller(target: str) -> None:
    """Add a "module:function" ``ControllerFactory`` to ``CONTROLLER_FACTORIES`` (idempotent)."""
    if ":" not in target:
        raise ValueError(f"a controller factory is 'module:function', got {target!r}")
    if target not in CONTROLLER_FACTORIES:
        CONTROLLER_FACTORIES.append(target)


def registered_controllers(env_id: str, objective: str) -> list[Controller]:
    """The ``CONTROLLER_FACTORIES`` controllers that apply to (env id, objective), in order."""
    controllers = []
    for target in CONTROLLER_FACTORIES:
        module, _, function = target.partition(":")
        controller = getattr(importlib.import_module(module), function)(env_id, objective)
        if controller is not None:
            controllers.append(controller)
    return controllers


def reference_controller(reference: Reference, label: str = OPTIMAL) -> Controller:
    """The reference's controls as an open-loop ``Controller``.

    One env step is one interval of the transcription (``optimal.replay.env_options``).
    """
    actions = env_actions(reference)
    options = env_options(reference)
    options.pop("reset_noise_scale")
    return Controller(label, lambda _env: open_loop_policy(actions), options)


def optimal_controller(env_id: str, objective: str) -> Controller | None:
    """The optimal reference of (env id, objective) played open loop; None without a reference."""
    name = REFERENCE_NAMES.get((env_id, objective))
    return None if name is None else reference_controller(load_reference(name))


def reference_effort(reference: Reference) -> float:
    """The reference's integral of sum(tau^2) [N^2 m^2 s] (its cost on "effort" objectives)."""
    return float(np.sum(reference.tau**2) * reference.time_step)


def shipped_policies(env_id: str, objective: str, directory: Path = TRAINED_DIR) -> list[Path]:
    """The JSON configs of the trained policies for (env id, objective) in ``directory``, sorted."""
    configs = []
    for path in sorted(Path(directory).glob("*.json")):
        config = json.loads(path.read_text())
        if (config.get("env_id") == env_id and config.get("objective") == objective
                and path.with_suffix(".zip").exists()):
            configs.append(path)
    return configs


def group_by_algorithm(configs: Sequence[Path]) -> dict[str, list[Path]]:
    """Trained-policy configs grouped by algorithm, each group sorted by seed."""
    groups: dict[str, list[tuple[int, Path]]] = {}
    for path in configs:
        config = json.loads(Path(path).read_text())
        groups.setdefault(config["algo"], []).append((int(config["seed"]), Path(path)))
    return {algo: [path for _, path in sorted(runs)] for algo, runs in groups.items()}


def shipped_algorithms(env_id: str, objective: str, directory: Path = TRAINED_DIR) -> set[str]:
    """The algorithms with at least one trained policy for (env id, objective) in ``directory``."""
    return set(group_by_algorithm(shipped_policies(env_id, objective, directory)))


def model_policy(model: Any, observe_time: bool = False
                 ) -> Callable[[gym.Env[Any, Any]], Policy]:  # fmt: skip
    """The ``Controller.make_policy`` of an SB3 model: its deterministic ``predict``.

    With ``observe_time`` the model is given the elapsed time as well
    (``baselines.time_input.counting_policy``).
    """
    def act(observation: Any) -> Any:
        return model.predict(observation, deterministic=True)[0]

    return lambda env: counting_policy(act, env) if observe_time else act


def load_policy(config_path: Path) -> Controller:
    """A trained policy (``model_policy``) as a ``Controller`` labelled by its algo.

    A policy trained with ``observe_time`` in its ``algo_kwargs`` (a distilled one) is given the
    elapsed time as well.

    Sets torch to one thread: a batch of one observation through a small network only loses
    to the threads' synchronisation (on a loaded machine, tens of times the one-thread time).
    """
    import torch

    from baselines.train import load_trained, read_training

    torch.set_num_threads(1)
    record = read_training(config_path)
    model = load_trained(record.algo, Path(config_path).with_suffix(".zip"))
    observe_time = bool(record.algo_kwargs.get("observe_time", False))
    training = Training(Path(config_path).stem, record.seed, record.commit,
                        record.num_timesteps, record.num_envs)  # fmt: skip
    return Controller(record.algo, model_policy(model, observe_time), dict(record.env_kwargs),
                      training)  # fmt: skip


def play(env_id: str, make_policy: Callable[[gym.Env[Any, Any]], Policy], seed: int,
         keep_trajectory: bool = False, **env_kwargs: Any) -> Episode:  # fmt: skip
    """One episode of ``gym.make(env_id, **env_kwargs)`` from ``reset(seed=seed)``.

    ``make_policy(env)`` is called once per episode (open-loop policies keep a step counter)
    with a separate env of the same configuration; each policy call is timed.
    """
    env = gym.make(env_id, **env_kwargs)
    policy = make_policy(env)
    env.close()
    compute = []

    def timed(observation: Any) -> Any:
        start = time.perf_counter()
        action = policy(observation)
        compute.append(time.perf_counter() - start)
        return action

    result = rollout(env_id, timed, seed=seed, **env_kwargs)
    info = result.last_info
    dt = float(info["elapsed_time"]) / max(result.num_steps, 1)
    brake_use = None
    if result.infos and "brake_engaged" in result.infos[0]:
        brake_use = BrakeUse.of([step["brake_engaged"] for step in result.infos],
                                [step["brake_impulse"] for step in result.infos], dt)
    trajectory = None
    if keep_trajectory:
        key = SCHEDULE_KEYS.get(env_id)
        trajectory = TrajectoryRecord(
            (dt * np.arange(result.num_steps + 1)).tolist(), np.asarray(result.q).tolist(),
            [float(step[key]) for step in result.infos] if key else [])
    return Episode(
        seed=seed, is_success=bool(info["is_success"]), elapsed_time=float(info["elapsed_time"]),
        effort=float(info["effort"]),
        solver_failures=sum(int(step["solver_status"] != 0) for step in result.infos),
        compute_per_step=float(np.mean(compute)) if compute else 0.0,
        episode_return=result.total_reward, num_steps=result.num_steps, trajectory=trajectory,
        brake_use=brake_use)


@dataclasses.dataclass(frozen=True)
class LoggedEpisode:
    """One line of the episode log: which study, row, run and condition the episode belongs to.

    Attributes:
        env_id, objective: the study. controller: the row's label. run: the run's index in its
        row. condition: the condition's label. nominal: the unperturbed start. episode: it.
    """

    env_id: str
    objective: str
    controller: str
    run: int
    condition: str
    nominal: bool
    episode: Episode

    @property
    def key(self) -> tuple[str, int, str, bool, int]:
        """(controller, run, condition, nominal, seed): what ``resume`` looks up."""
        return self.controller, self.run, self.condition, self.nominal, self.episode.seed


def read_log(path: Path | None, env_id: str, objective: str
             ) -> dict[tuple[str, int, str, bool, int], Episode]:  # fmt: skip
    """The logged episodes of the study (env id, objective) in ``path``, by ``LoggedEpisode.key``.

    A missing file is an empty one; a line cut short (a run killed while writing) is skipped.
    """
    from pydantic import ValidationError

    from baselines.records import from_json

    episodes = {}
    lines = path.read_text().splitlines() if path is not None and path.exists() else []
    for line in lines:
        try:
            logged = from_json(LoggedEpisode, json.loads(line))
        except (json.JSONDecodeError, ValidationError):
            continue
        if (logged.env_id, logged.objective) == (env_id, objective):
            episodes[logged.key] = logged.episode
    return episodes


def append_log(path: Path, logged: LoggedEpisode) -> None:
    """One JSON line at the end of ``path``, after a newline if its last line was cut short."""
    from baselines.records import to_json

    with path.open("a+b") as stream:
        if stream.seek(0, os.SEEK_END):
            stream.seek(-1, os.SEEK_END)
            if stream.read(1) != b"\n":
                stream.write(b"\n")
        stream.write(json.dumps(to_json(logged)).encode() + b"\n")


def controller_rows(env_id: str, objective: str, trained_dir: Path = TRAINED_DIR,
                    extra: Sequence[Controller] = (), only: Sequence[str] | None = None
                    ) -> list[tuple[str, list[Controller]]]:  # fmt: skip
    """(label, runs) per row: the registered controllers, each trained algorithm, ``extra``.

    A trained algorithm has one run per seed. Only the labels in ``only`` (None: all; an
    unknown label: ValueError).
    """
    trained = group_by_algorithm(shipped_policies(env_id, objective, trained_dir))
    registered = [(c.label, [c]) for c in registered_controllers(env_id, objective)]
    rows: list[tuple[str, Any]] = [*registered, *trained.items(),
                                   *((c.label, [c]) for c in extra)]
    unknown = sorted(set(only or ()) - {label for label, _ in rows})
    if unknown:
        raise ValueError(f"no controller {', '.join(map(repr, unknown))} for {env_id} objective "
                         f"{objective!r}; known: {', '.join(label for label, _ in rows)}")
    return [(label, [load_policy(run) if label in trained else run for run in runs])
            for label, runs in rows if only is None or label in only]  # policies loaded last


def evaluate(
    env_id: str,
    objective: str,
    conditions: Sequence[Condition] = (Condition(),),
    num_starts: int = 20,
    *,
    trained_dir: Path = TRAINED_DIR,
    extra_controllers: Sequence[Controller] = (),
    only: Sequence[str] | None = None,
    nominal: bool = False,
    log_path: Path | None = None,
    resume: bool = False,
    show_bar: bool = False,
) -> Study:
    """Play every row's runs under every condition (see the module docstring).

    Args:
        env_id: a mission env id. objective: "time" or "effort".
        conditions: what each run is played under (``Condition``; a mismatch label must be
            one of ``MISMATCHES[env_id]``).
        num_starts: perturbed starts per run (reset seeds 0 ... num_starts - 1).
        trained_dir: where the trained policies are (``shipped_policies``).
        extra_controllers: untrained controllers after the registered ones and the trained.
        only: the row labels to play (None: all), for a study completed row by row (``merge``).
        nominal: also play each run from the unperturbed start, and keep the trajectories of
            the nominal episodes and of the first run's perturbed ones (for the plots).
        log_path: a JSON-lines file each finished episode is appended to (``LoggedEpisode``).
        resume: take the episodes already in ``log_path`` instead of playing them again.
        show_bar: a tqdm bar over the episodes on stderr.

    Raises:
        ValueError: no reference for (env id, objective), an unknown mismatch or row label.
    """
    if (env_id, objective) not in REFERENCE_NAMES:
        known = ", ".join(f"{e} {t}" for e, t in REFERENCE_NAMES)
        raise ValueError(f"no optimal reference for {env_id} objective {objective!r}; "
                         f"known: {known}")
    unknown = [c.mismatch for c in conditions
               if c.mismatch is not None and c.mismatch not in MISMATCHES[env_id]]
    if unknown:
        raise ValueError(f"unknown mismatch {unknown} for {env_id}; known: "
                         f"{list(MISMATCHES[env_id])}")
    reference = load_reference(REFERENCE_NAMES[(env_id, objective)])
    optimal_time, optimal_effort = reference.final_time, reference_effort(reference)
    playing = controller_rows(env_id, objective, trained_dir, extra_controllers, only)
    finished = read_log(log_path, env_id, objective) if resume else {}
    commit = git_commit()
    total = (num_starts + nominal) * len(conditions) * sum(len(runs) for _, runs in playing)
    bar = tqdm(total=total, desc=f"{env_id.split('/')[-1]} {objective}", unit="episode",
               mininterval=10.0, disable=not show_bar)  # fmt: skip

    def episode(label: str, index: int, controller: Controller, condition: Condition,
                seed: int, is_nominal: bool) -> Episode:  # fmt: skip
        key = (label, index, condition.label, is_nominal, seed)
        if key not in finished:
            kwargs = {**controller.env_kwargs,
                      "reset_noise_scale": 0.0 if is_nominal else condition.scale}
            if condition.mismatch is not None:
                kwargs["parameters"] = MISMATCHES[env_id][condition.mismatch]()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                finished[key] = play(env_id, controller.make_policy, seed,
                                     nominal and (is_nominal or index == 0), **kwargs)
            if log_path is not None:
                append_log(log_path, LoggedEpisode(env_id, objective, label, index, condition.label,
                                                   is_nominal, finished[key]))  # fmt: skip
        bar.update()
        return finished[key]

    rows = []
    for label, controllers in playing:
        runs = []
        for condition in conditions:
            for index, controller in enumerate(controllers):
                episodes = [episode(label, index, controller, condition, seed, False)
                            for seed in range(num_starts)]
                runs.append(Run(
                    condition, Scores.of(episodes, optimal_time, optimal_effort), episodes,
                    episode(label, index, controller, condition, 0, True) if nominal else None,
                    controller.training, commit))  # fmt: skip
        rows.append(Row(label, controllers[0].training is not None, runs))
    bar.close()
    return Study(env_id, objective, reference.name, optimal_time, optimal_effort, num_starts,
                 list(conditions), rows)


def aggregate(study: Study, reps: int | None = None) -> Study:
    """``study`` with each row's missing ``Aggregate``s computed from its runs (``iqm_interval``).

    ``reps``: bootstrap replications of the IQM intervals (default ``BOOTSTRAP_REPS``; 0: no
    interval, as the robustness table shows means only). Aggregates already there are kept.
    """
    from baselines.aggregate import BOOTSTRAP_REPS, iqm_interval

    reps = BOOTSTRAP_REPS if reps is None else reps

    def estimates(row: Row, condition: str) -> Aggregate:
        runs = row.at(condition)
        return row.aggregate(condition) or Aggregate(condition, *(
            iqm_interval([getattr(run.scores, score) for run in runs], reps=reps)
            for score in SCORES))  # fmt: skip

    return dataclasses.replace(study, rows=[
        dataclasses.replace(row, aggregates=[estimates(row, c.label) for c in study.conditions
                                             if row.at(c.label) or row.aggregate(c.label)])
        for row in study.rows])  # fmt: skip


def merge(old: Study, new: Study, shipped: Collection[str] | None = None) -> Study:
    """``old`` with ``new``'s rows added, or replacing the same row's runs under a condition.

    Rows keep ``old``'s order, new ones follow; conditions are ordered scales ascending, then
    the mismatches in ``MISMATCHES`` order. A condition ``new`` played for a row replaces
    that row's runs and aggregate there (``aggregate`` recomputes it); the others stay. With
    ``shipped`` (the algorithms that have trained policies now, ``shipped_algorithms``) an
    old trained row of another algorithm is dropped: its policies were withdrawn.

    Raises:
        ValueError: the studies differ in env, objective, reference or number of starts.
    """
    for key in ("env_id", "objective", "reference", "optimal_time", "optimal_effort", "num_starts"):
        if getattr(old, key) != getattr(new, key):
            raise ValueError(f"cannot merge studies with different {key}: "
                             f"{getattr(old, key)!r} and {getattr(new, key)!r}")
    order = list(MISMATCHES[new.env_id])
    conditions = sorted(set(old.conditions) | set(new.conditions), key=lambda c: (
        c.mismatch is not None, c.scale if c.mismatch is None else order.index(c.mismatch)))
    rows = {row.label: row for row in old.rows
            if shipped is None or not row.trained or row.label in shipped}
    for row in new.rows:
        kept = rows.get(row.label, Row(row.label, row.trained, []))
        played = {run.condition for run in row.runs}
        runs = [run for run in kept.runs if run.condition not in played] + row.runs
        rows[row.label] = Row(row.label, row.trained, sorted(
            runs, key=lambda run: (conditions.index(run.condition), run.seed or 0)), [
            a for a in kept.aggregates if a.condition not in {c.label for c in played}])
    return dataclasses.replace(new, conditions=conditions, rows=list(rows.values()))


__all__ = [
    "CONTROLLER_FACTORIES", "DIFF_DRIVE", "DIFF_DRIVE_EFFORT_V1", "DIFF_DRIVE_V1", "MANIPULATOR",
    "MANIPULATOR_V1", "MISMATCHES", "OBJECTIVES",
    "REFERENCE_NAMES", "SCALES", "SCHEDULE_KEYS", "SCORES", "TRAINED_DIR", "DISTILLED_DIR",
    "Controller",
    "ControllerFactory", "LoggedEpisode", "aggregate", "append_log", "controller_rows",
    "evaluate", "group_by_algorithm", "load_policy", "merge", "model_policy", "optimal_controller",
    "play", "read_log", "reference_controller", "reference_effort", "register_controller",
    "registered_controllers", "shipped_algorithms", "shipped_policies",
]
