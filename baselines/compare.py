"""RL policies against the optimal reference in the same environment, over training seeds.

``compare("mdi_envs/DiffDriveRobot-v0", "effort")`` plays every trained policy of that env and
objective (``baselines/trained/STEM.zip`` with its ``STEM.json`` config; one per training seed,
``{env}_{objective}_{algo}_seed{S}``), deterministically, from ``reset(seed=s)`` for the starts
``0 ... num_seeds - 1``: each reset draws a small start perturbation (the env's
``reset_noise_scale``, 0.01 rad, rad/s or m, m/s by default). The controllers that are not
trained (``CONTROLLER_FACTORIES``: the optimal reference, played open loop through the same env
id with one env step per interval of the transcription, ``optimal.replay.env_options``; room
for more, e.g. a model-based MPC) are played from the nominal start and the same starts.

Scores of one run (one training seed, or a controller): the success rate over the perturbed
starts, and over its successful episodes the time to the goal [s] and the effort (integral of
the squared torques [N^2 m^2 s]) as ratios to the optimum's (``reference.final_time`` and the
reference's effort). Time to the goal is the episode's ``elapsed_time`` when it terminates at
the goal ("time" objectives) or its fixed horizon ("effort"). Per algorithm, over its runs
(``baselines.aggregate``, rliable): the interquartile mean and 95 % stratified-bootstrap
confidence interval of each score; one run is reported as n=1 without interval.

Outputs (``write_comparison``): ``compare_{env}_{objective}.json`` (every run's episodes, summaries
and aggregates, the reference's metadata), ``compare_{env}_{objective}.png`` (the nominal
trajectories of every controller over the optimum's, with brake schedules or slip modes, and
the scores), ``seeds_{env}_{objective}.png`` (performance profiles over runs and training curves
with CI bands, ``baselines.seed_plots``) and the Markdown table ``markdown_table`` prints.
"""

from __future__ import annotations

import importlib
import json
import time
import warnings
from collections.abc import Callable, Collection, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Protocol

import gymnasium as gym
import numpy as np

from mdi_envs.rollout import Policy, open_loop_policy, rollout
from optimal.references import Reference, load_reference
from optimal.replay import env_actions, env_options

TRAINED_DIR = Path(__file__).parent / "trained"
"""Where the shipped policies live: ``STEM.zip`` + ``STEM.json`` (see ``baselines.train``)."""

REFERENCE_NAMES = {
    ("mdi_envs/BlockableManipulator-v0", "time"): "manipulator_time",
    ("mdi_envs/DiffDriveRobot-v0", "time"): "diff_drive_time",
    ("mdi_envs/DiffDriveRobot-v0", "effort"): "diff_drive_effort",
}
"""(env id, objective) -> the optimal reference it is measured against."""

OBJECTIVES = {"mdi_envs/BlockableManipulator-v0": ("time",),
         "mdi_envs/DiffDriveRobot-v0": ("time", "effort")}  # fmt: skip
"""The objectives of each mission environment."""

SCHEDULE_KEYS = {"mdi_envs/BlockableManipulator-v0": "brake_engaged",
                 "mdi_envs/DiffDriveRobot-v0": "slip_mode"}  # fmt: skip
"""The per-step ``info`` entry drawn as a schedule: brake engaged (0/1) or slip mode (2/3/5)."""

OPTIMAL = "optimal (open loop)"
"""The label of the reference in tables and plots."""

TRAJECTORY_FIELDS = ("time", "q", "schedule")
"""The array fields of an ``Episode`` (kept in the JSON for nominal episodes only)."""

SCORES = ("success_rate", "time_ratio", "effort_ratio")
"""The per-run scores aggregated over runs (``summarize`` keys)."""


@dataclass(frozen=True)
class Controller:
    """A controller that is not trained (no seeds: one run per comparison).

    Attributes:
        label: its row in tables and plots.
        make_policy: called once per episode with a ``gym.make(env_id, **env_kwargs)`` of the
            played configuration (a separate instance, e.g. to read the model and ``dt``);
            returns the policy ``obs -> action`` for that episode.
        env_kwargs: the ``gym.make`` arguments it is played with (``reset_noise_scale`` is set
            by the comparison).
    """

    label: str
    make_policy: Callable[[gym.Env[Any, Any]], Policy]
    env_kwargs: dict[str, Any] = field(default_factory=dict)


CONTROLLER_FACTORIES = ("baselines.compare:optimal_controller",)
"""The untrained controller rows, as "module:function" (imported on use); each function takes
(env id, objective) and returns a ``Controller``, or None where it does not apply. A model-based
controller (e.g. an MPC in ``optimal/``) joins every comparison by adding its entry here."""


@dataclass
class Episode:
    """One episode of one controller.

    Attributes:
        seed: the reset seed. perturbed: whether the start was perturbed (reset noise > 0).
        is_success: ended at the goal. elapsed_time: simulated time at the end [s].
        effort: integral of sum(tau^2) [N^2 m^2 s]. episode_return: sum of rewards.
        num_steps: env steps. solver_failures: steps whose contact solve did not converge.
        time: (num_steps + 1,) [s]. q: (num_steps + 1, n) coordinates.
        schedule: (num_steps,) brake engaged (0/1) or slip mode (2/3/5) per step.
        compute_per_step: mean wall time of one policy call [s] (an MPC's re-solve, a
            network's forward pass).
    """

    seed: int
    perturbed: bool
    is_success: bool
    elapsed_time: float
    effort: float
    episode_return: float
    num_steps: int
    solver_failures: int
    time: np.ndarray
    q: np.ndarray
    schedule: np.ndarray
    compute_per_step: float = 0.0

    def scores(self) -> dict[str, Any]:
        """The scalar fields (for JSON)."""
        return {key: value for key, value in asdict(self).items()
                if key not in TRAJECTORY_FIELDS}  # fmt: skip

    def record(self) -> dict[str, Any]:
        """The scalar fields and the trajectory (for JSON; ``from_record`` reads it back)."""
        return {**self.scores(), "trajectory": {key: getattr(self, key).tolist()
                                                for key in TRAJECTORY_FIELDS}}

    @classmethod
    def from_record(cls, record: dict[str, Any]) -> Episode:
        """An ``Episode`` from ``scores()`` or ``record()`` (trajectory empty if not stored)."""
        trajectory = record.get("trajectory", {})
        fields: dict[str, Any] = {key: value for key, value in record.items()
                                  if key != "trajectory"}
        fields.update({key: np.asarray(trajectory.get(key, []), dtype=float)
                       for key in TRAJECTORY_FIELDS})
        return cls(**fields)


def play(env_id: str, make_policy: Callable[[gym.Env[Any, Any]], Policy], seed: int,
         perturbed: bool, **env_kwargs: Any) -> Episode:  # fmt: skip
    """One episode of ``gym.make(env_id, **env_kwargs)`` from ``reset(seed=seed)``.

    ``make_policy(env)`` is called once per episode (open-loop policies keep a step counter)
    with a separate env of the same configuration; ``perturbed=False`` sets
    ``reset_noise_scale = 0`` (the nominal start).
    """
    if not perturbed:
        env_kwargs = {**env_kwargs, "reset_noise_scale": 0.0}
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
    key = SCHEDULE_KEYS.get(env_id)
    schedule = np.array([step[key] for step in result.infos] if key else [], dtype=float)
    return Episode(
        seed=seed, perturbed=perturbed,
        is_success=bool(info["is_success"]), elapsed_time=float(info["elapsed_time"]),
        effort=float(info["effort"]), episode_return=result.total_reward,
        num_steps=result.num_steps,
        solver_failures=sum(int(step["solver_status"] != 0) for step in result.infos),
        time=dt * np.arange(result.num_steps + 1), q=result.q, schedule=schedule,
        compute_per_step=float(np.mean(compute)) if compute else 0.0,
    )


def reference_controller(reference: Reference, label: str = OPTIMAL) -> Controller:
    """The reference's controls as an open-loop ``Controller``.

    One env step is one interval of the transcription (``optimal.replay.env_options``); the
    start perturbation is the env's default (``reset_noise_scale`` is left to the caller).
    """
    actions = env_actions(reference)
    options = env_options(reference)
    options.pop("reset_noise_scale")
    return Controller(label, lambda _env: open_loop_policy(actions), options)


def optimal_controller(env_id: str, objective: str) -> Controller | None:
    """The optimal reference of (env id, objective) played open loop; None without a reference."""
    name = REFERENCE_NAMES.get((env_id, objective))
    return None if name is None else reference_controller(load_reference(name))


def registered_controllers(env_id: str, objective: str) -> list[Controller]:
    """The ``CONTROLLER_FACTORIES`` controllers that apply to (env id, objective), in order."""
    controllers = []
    for target in CONTROLLER_FACTORIES:
        module, _, function = target.partition(":")
        controller = getattr(importlib.import_module(module), function)(env_id, objective)
        if controller is not None:
            controllers.append(controller)
    return controllers


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


def load_policy(config_path: Path) -> tuple[Controller, dict[str, Any]]:
    """A trained policy (deterministic ``predict``) as a ``Controller``, and its config."""
    from baselines.train import load_trained

    config = json.loads(Path(config_path).read_text())
    model = load_trained(config["algo"], Path(config_path).with_suffix(".zip"))

    def act(obs: Any) -> Any:
        return model.predict(obs, deterministic=True)[0]

    return Controller(config["algo"], lambda _env: act, dict(config["env_kwargs"])), config


class EpisodeScores(Protocol):
    """What ``summarize`` reads of an episode (an ``Episode``, or a stored one's scores)."""

    @property
    def is_success(self) -> bool:
        """Ended at the goal."""

    @property
    def elapsed_time(self) -> float:
        """Simulated time at the end [s]."""

    @property
    def effort(self) -> float:
        """Integral of sum(tau^2) [N^2 m^2 s]."""

    @property
    def solver_failures(self) -> int:
        """Steps whose contact solve did not converge."""

    @property
    def compute_per_step(self) -> float:
        """Mean wall time of one policy call [s]."""


def summarize(episodes: Sequence[EpisodeScores], optimal_time: float, optimal_effort: float
              ) -> dict[str, Any]:  # fmt: skip
    """Success rate and, over the successes, time and effort as ratios to the optimum.

    Returns:
        {"episodes", "success_rate", "time_ratio" (mean), "time_ratio_median",
        "effort_ratio" (mean), "mean_time" [s], "mean_effort" [N^2 m^2 s],
        "solver_failures", "compute_per_step" [s] (mean over the episodes)}; the ratios are
        None without a success.
    """
    wins = [e for e in episodes if e.is_success]
    times = np.array([e.elapsed_time for e in wins])
    efforts = np.array([e.effort for e in wins])
    return {
        "episodes": len(episodes),
        "success_rate": len(wins) / len(episodes) if episodes else 0.0,
        "time_ratio": float(np.mean(times) / optimal_time) if wins else None,
        "time_ratio_median": float(np.median(times) / optimal_time) if wins else None,
        "effort_ratio": float(np.mean(efforts) / optimal_effort) if wins else None,
        "mean_time": float(np.mean(times)) if wins else None,
        "mean_effort": float(np.mean(efforts)) if wins else None,
        "solver_failures": int(sum(e.solver_failures for e in episodes)),
        "compute_per_step": float(np.mean([e.compute_per_step for e in episodes]))
        if episodes else 0.0,
    }


def aggregate_runs(runs: Sequence[dict[str, Any]], reps: int | None = None) -> dict[str, Any]:
    """Per score of ``SCORES``: IQM and 95 % CI over the runs' summaries (``iqm_interval``)."""
    from baselines.aggregate import BOOTSTRAP_REPS, iqm_interval

    return {score: iqm_interval([run["summary"][score] for run in runs],
                                reps=BOOTSTRAP_REPS if reps is None else reps)
            for score in SCORES}  # fmt: skip


def evaluate_controller(env_id: str, controller: Controller, seeds: Sequence[int]
                        ) -> tuple[Episode, list[Episode]]:  # fmt: skip
    """The nominal episode (no start noise, seed 0) and one perturbed episode per seed."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nominal = play(env_id, controller.make_policy, 0, False, **controller.env_kwargs)
        perturbed = [play(env_id, controller.make_policy, int(seed), True,
                          **controller.env_kwargs) for seed in seeds]  # fmt: skip
    return nominal, perturbed


def compare(
    env_id: str,
    objective: str,
    num_seeds: int = 20,
    policies: Sequence[Path] | None = None,
    extra_controllers: Sequence[Controller] = (),
    log: Callable[[str], None] | None = None,
    trained_dir: Path = TRAINED_DIR,
    bootstrap_reps: int | None = None,
    only: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Evaluate the controllers and every run of every trained algorithm on the same starts.

    Args:
        env_id: a mission environment id. objective: "time" or "effort".
        num_seeds: perturbed starts per run (seeds 0 ... num_seeds - 1).
        policies: trained-policy JSON configs (default: ``shipped_policies(env_id, objective,
            trained_dir)``), one run each, grouped by algorithm.
        extra_controllers: more untrained controllers after the registered ones
            (``CONTROLLER_FACTORIES``; tests use a random policy and the reference's controls).
        log: progress lines (default: none).
        trained_dir: where ``shipped_policies`` looks.
        bootstrap_reps: bootstrap replications (default ``baselines.aggregate.BOOTSTRAP_REPS``).
        only: the row labels to play (e.g. ["PPO", "HybridPPO"]; None: all), for a comparison
            completed row by row (``merge_comparisons``); an unknown label is a ValueError.

    Returns:
        {"env_id", "objective", "reference", "optimal_time" [s], "optimal_effort" [N^2 m^2 s],
        "seeds", "controllers": [{"label", "algo", "trained" (bool), "runs": [{"seed"
        (training seed, None for an untrained controller), "config", "summary", "nominal",
        "episodes"}], "aggregate": {score: ``iqm_interval``}}]}, the episodes as ``Episode``
        objects (``write_comparison`` turns them into JSON).
    """
    if (env_id, objective) not in REFERENCE_NAMES:
        known = ", ".join(f"{e} {t}" for e, t in REFERENCE_NAMES)
        raise ValueError(f"no optimal reference for {env_id} objective {objective!r}; "
                         f"known: {known}")
    say = log or (lambda _: None)
    reference = load_reference(REFERENCE_NAMES[(env_id, objective)])
    optimal_time, optimal_effort = reference.final_time, reference_effort(reference)
    seeds = list(range(num_seeds))
    configs = shipped_policies(env_id, objective, trained_dir) if policies is None else policies
    groups: list[tuple[str, bool, list[tuple[Controller, dict[str, Any]]]]] = [
        (c.label, False, [(c, {})]) for c in registered_controllers(env_id, objective)]
    for algo, paths in group_by_algorithm(configs).items():
        groups.append((algo, True, [load_policy(path) for path in paths]))
    groups += [(c.label, False, [(c, {})]) for c in extra_controllers]
    require_known_labels(only, [label for label, _, _ in groups], env_id, objective)
    groups = [group for group in groups if only is None or group[0] in only]
    rows = []
    for label, trained, members in groups:
        runs = []
        for controller, config in members:
            seed = config.get("seed")
            say(f"{env_id} {objective}: {label}" + (f" seed {seed}" if trained else "")
                + f", nominal start + {num_seeds} perturbed starts")  # fmt: skip
            nominal, episodes = evaluate_controller(env_id, controller, seeds)
            runs.append({"seed": seed, "config": config, "nominal": nominal,
                         "episodes": episodes,
                         "summary": summarize(episodes, optimal_time, optimal_effort)})  # fmt: skip
        rows.append({"label": label, "algo": label if trained else "controller",
                     "trained": trained, "runs": runs,
                     "aggregate": aggregate_runs(runs, bootstrap_reps)})  # fmt: skip
    return {"env_id": env_id, "objective": objective, "reference": reference.name,
            "optimal_time": optimal_time, "optimal_effort": optimal_effort, "seeds": seeds,
            "controllers": rows}  # fmt: skip


def require_known_labels(only: Sequence[str] | None, known: Sequence[str], env_id: str,
                         objective: str) -> None:
    """Raise ValueError naming the labels of ``only`` that are not in ``known``."""
    unknown = sorted(set(only or ()) - set(known))
    if unknown:
        raise ValueError(f"no controller {', '.join(map(repr, unknown))} for {env_id} objective "
                         f"{objective!r}; known: {', '.join(known)}")


def budget_text(row: dict[str, Any]) -> str:
    """A row's training budget and seeds, e.g. "10^7 steps, 64 envs, seeds 0-4" ("" untrained)."""
    if not row["trained"]:
        return ""
    configs = [run["config"] for run in row["runs"]]
    steps = {int(c.get("num_timesteps", c.get("total_timesteps", 0))) for c in configs}
    seeds = sorted(int(c["seed"]) for c in configs)
    seed_text = (f"seed {seeds[0]}" if len(seeds) == 1 else
                 f"seeds {seeds[0]}-{seeds[-1]}" if seeds == list(range(seeds[0], seeds[-1] + 1))
                 else "seeds " + ",".join(map(str, seeds)))  # fmt: skip
    budget = "/".join(sorted({f"{s:.2g}" for s in steps}))
    return f"{budget} steps, {configs[0].get('num_envs')} envs, {seed_text}"


def interval_text(estimate: dict[str, Any], percent: bool = False) -> str:
    """"IQM [low, high] (n=k)", "value (n=1, no CI)" or "-" (no run with a score)."""
    if estimate["iqm"] is None:
        return "-"
    show = (lambda v: f"{100 * v:.0f} %") if percent else (lambda v: f"{v:.2f}")
    missing = f", {estimate['missing']} without" if estimate["missing"] else ""
    if estimate["ci"] is None:
        return f"{show(estimate['iqm'])} (n={estimate['n']}, no CI{missing})"
    low, high = estimate["ci"]
    return f"{show(estimate['iqm'])} [{show(low)}, {show(high)}] (n={estimate['n']}{missing})"


def _nominal_text(row: dict[str, Any]) -> str:
    if row["trained"]:
        wins = sum(run["nominal"].is_success for run in row["runs"])
        return f"{wins} of {len(row['runs'])} runs succeed"
    nominal = row["runs"][0]["nominal"]
    return (f"success, {nominal.elapsed_time:.2f} s, effort {nominal.effort:.3g}"
            if nominal.is_success else "fails")  # fmt: skip


def _compute_text(row: dict[str, Any]) -> str:
    """The mean wall time of one policy call over the row's perturbed episodes."""
    times = [run["summary"]["compute_per_step"] for run in row["runs"]]
    seconds = float(np.mean(times))
    return f"{1e3 * seconds:.3g} ms" if seconds < 1.0 else f"{seconds:.2f} s"


def markdown_table(comparisons: Sequence[dict[str, Any]]) -> str:
    """One row per env x objective x controller: IQM [95 % CI] over runs (n) of each score.

    A trained algorithm's runs are its training seeds; an untrained controller is one run
    (its cells show the value alone, "(controller)").
    """
    lines = ["| env | objective | controller | runs | success (perturbed starts), IQM [95 % CI] | "
             "time / optimal | effort / optimal | nominal start | compute / step | "
             "training budget |",
             "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for comparison in comparisons:
        env = comparison["env_id"].split("/")[-1]
        starts = len(comparison["seeds"])
        for row in comparison["controllers"]:
            aggregate = row["aggregate"]
            if row["trained"]:
                runs = f"{len(row['runs'])} seed{'s' * (len(row['runs']) != 1)} x {starts} starts"
                cells = [interval_text(aggregate["success_rate"], percent=True),
                         interval_text(aggregate["time_ratio"]),
                         interval_text(aggregate["effort_ratio"])]  # fmt: skip
            else:
                runs = f"controller, {starts} starts"
                cells = [f"{100 * aggregate['success_rate']['iqm']:.0f} %",
                         *(f"{v['iqm']:.2f}" if v["iqm"] is not None else "-"
                           for v in (aggregate["time_ratio"], aggregate["effort_ratio"]))]
            lines.append(f"| {env} | {comparison['objective']} | {row['label']} | {runs} | "
                         + " | ".join(cells)
                         + f" | {_nominal_text(row)} | {_compute_text(row)} | "
                         f"{budget_text(row)} |")  # fmt: skip
    return "\n".join(lines)


def comparison_record(comparison: dict[str, Any]) -> dict[str, Any]:
    """The comparison as plain JSON; ``merge_comparisons`` reads it back.

    Perturbed episodes as their scores, nominal episodes with their trajectories.
    """
    record = {k: v for k, v in comparison.items() if k != "controllers"}
    record["controllers"] = [
        {"label": row["label"], "algo": row["algo"], "trained": row["trained"],
         "aggregate": row["aggregate"],
         "runs": [{"seed": run["seed"], "config": run["config"], "summary": run["summary"],
                   "nominal": run["nominal"].record(),
                   "episodes": [e.scores() for e in run["episodes"]]}
                  for run in row["runs"]]}
        for row in comparison["controllers"]
    ]  # fmt: skip
    return record


def merge_comparisons(old: dict[str, Any], new: dict[str, Any],
                      shipped: Collection[str] | None = None) -> dict[str, Any]:
    """``new``'s rows over ``old``'s (a ``comparison_record``, e.g. the JSON in the output).

    Rows with the same label are replaced, the others kept in ``old``'s order and ``new``'s
    added after them; with ``shipped`` (the algorithms that have trained policies now,
    ``shipped_algorithms``) a trained row of another algorithm is dropped (its policies were
    withdrawn). Both must compare the same env, objective, reference (same optimum) and starts.
    Kept rows come back as ``Episode`` objects (perturbed episodes without trajectories).
    """
    for key in ("env_id", "objective", "reference", "optimal_time", "optimal_effort", "seeds"):
        if old.get(key) != new[key]:
            raise ValueError(f"cannot merge comparisons with different {key}: "
                             f"{old.get(key)!r} and {new[key]!r}")
    replaced = {row["label"]: row for row in new["controllers"]}
    rows = []
    for row in old["controllers"]:
        if row["label"] in replaced:
            rows.append(replaced.pop(row["label"]))
            continue
        if shipped is not None and row.get("trained") and row["label"] not in shipped:
            continue
        runs = [{**run, "nominal": Episode.from_record(run["nominal"]),
                 "episodes": [Episode.from_record(e) for e in run["episodes"]]}
                for run in row["runs"]]  # fmt: skip
        rows.append({**row, "runs": runs})
    return {**new, "controllers": rows + list(replaced.values())}


def write_comparison(comparison: dict[str, Any], output: Path,
                     trained_dir: Path = TRAINED_DIR) -> list[Path]:  # fmt: skip
    """Write ``compare_{env}_{objective}.{json,png,md}`` and ``seeds_{env}_{objective}.png``.

    The ``.md`` is the comparison's ``markdown_table`` (``collect_tables`` joins them).

    The training curves of ``seeds_*.png`` come from the runs' ``STEM_episodes.csv`` in
    ``trained_dir`` where present.

    Returns:
        The written paths.
    """
    from baselines.compare_plots import plot_comparison
    from baselines.seed_plots import plot_seeds

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    stem = f"{comparison['env_id'].split('/')[-1]}_{comparison['objective']}"
    json_path = output / f"compare_{stem}.json"
    json_path.write_text(json.dumps(comparison_record(comparison), indent=1, default=str) + "\n")
    png_path = output / f"compare_{stem}.png"
    plot_comparison(comparison, png_path)
    seeds_path = output / f"seeds_{stem}.png"
    plot_seeds(comparison, seeds_path, trained_dir)
    table_path = output / f"compare_{stem}.md"
    table_path.write_text(markdown_table([comparison]) + "\n")
    return [json_path, png_path, seeds_path, table_path]


def collect_tables(output: Path) -> str:
    """One Markdown table of every ``compare_*.md`` in ``output`` (env x objective, sorted).

    A comparison rerun for one env x objective so keeps the others' rows in ``compare.md``.
    """
    header: list[str] = []
    rows: list[str] = []
    for path in sorted(Path(output).glob("compare_*.md")):
        lines = path.read_text().strip().splitlines()
        header, rows = lines[:2], rows + lines[2:]
    return "\n".join(header + rows)


__all__ = [
    "CONTROLLER_FACTORIES", "OPTIMAL", "REFERENCE_NAMES", "SCORES", "OBJECTIVES", "TRAINED_DIR",
    "TRAJECTORY_FIELDS",
    "Controller", "Episode", "EpisodeScores", "aggregate_runs", "collect_tables", "compare",
    "comparison_record", "evaluate_controller", "group_by_algorithm", "interval_text",
    "load_policy", "markdown_table", "merge_comparisons", "optimal_controller", "play",
    "reference_controller", "reference_effort", "registered_controllers", "require_known_labels",
    "shipped_algorithms", "shipped_policies", "summarize", "write_comparison",
]
