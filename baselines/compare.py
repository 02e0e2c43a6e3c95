"""RL policies against the optimal reference in the same environment, over many seeds.

``compare("mdi_envs/DiffDriveRobot-v0", "effort")`` plays every shipped policy of that env and
task (``baselines/trained/*.zip`` with its JSON config), deterministically, from ``reset(seed=s)``
for the seeds ``0 ... num_seeds - 1``: each reset draws a small start perturbation (the env's
``reset_noise_scale``, 0.01 rad, rad/s or m, m/s by default). The optimal reference
(``optimal/references``) is played open loop through the same environment id, configured so that
one env step is one interval of the transcription (``optimal.replay.env_options``): once from the
nominal start (its ratio is 1 by construction) and from the same perturbed starts.

Scores, per controller: the success rate, and over the successful episodes the time to the goal
[s] and the effort (integral of the squared torques [N^2 m^2 s]) as ratios to the optimum's
(``reference.final_time`` and the reference's effort). Time to the goal is the episode's
``elapsed_time`` when it terminates at the goal ("time" tasks) or its fixed horizon ("effort").

Outputs (``write_comparison``): ``compare_{env}_{task}.json`` (every episode's scores, the
summaries, the reference's metadata), ``compare_{env}_{task}.png`` (the nominal trajectories of
every controller over the optimum's, with brake schedules or slip modes) and the Markdown table
``markdown_table`` prints.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

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
"""(env id, task) -> the optimal reference it is measured against."""

TASKS = {"mdi_envs/BlockableManipulator-v0": ("time",),
         "mdi_envs/DiffDriveRobot-v0": ("time", "effort")}  # fmt: skip
"""The tasks of each mission environment."""

SCHEDULE_KEYS = {"mdi_envs/BlockableManipulator-v0": "brake_engaged",
                 "mdi_envs/DiffDriveRobot-v0": "slip_mode"}  # fmt: skip
"""The per-step ``info`` entry drawn as a schedule: brake engaged (0/1) or slip mode (2/3/5)."""

OPTIMAL = "optimal (open loop)"
"""The label of the reference in tables and plots."""


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

    def scores(self) -> dict[str, Any]:
        """The scalar fields (for JSON)."""
        return {key: value for key, value in asdict(self).items()
                if key not in ("time", "q", "schedule")}  # fmt: skip


def play(env_id: str, make_policy: Callable[[], Policy], seed: int, perturbed: bool,
         **env_kwargs: Any) -> Episode:  # fmt: skip
    """One episode of ``gym.make(env_id, **env_kwargs)`` from ``reset(seed=seed)``.

    ``make_policy()`` is called once per episode (open-loop policies keep a step counter);
    ``perturbed=False`` sets ``reset_noise_scale = 0`` (the nominal start).
    """
    if not perturbed:
        env_kwargs = {**env_kwargs, "reset_noise_scale": 0.0}
    result = rollout(env_id, make_policy(), seed=seed, **env_kwargs)
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
    )


def reference_controller(reference: Reference) -> tuple[Callable[[], Policy], dict[str, Any]]:
    """The reference's controls as an open-loop policy factory and its ``gym.make`` arguments.

    One env step is one interval of the transcription (``optimal.replay.env_options``); the
    start perturbation is the env's default (``reset_noise_scale`` is left to the caller).
    """
    actions = env_actions(reference)
    options = env_options(reference)
    options.pop("reset_noise_scale")
    return (lambda: open_loop_policy(actions)), options


def reference_effort(reference: Reference) -> float:
    """The reference's integral of sum(tau^2) [N^2 m^2 s] (its cost on "effort" tasks)."""
    return float(np.sum(reference.tau**2) * reference.time_step)


def shipped_policies(env_id: str, task: str, directory: Path = TRAINED_DIR) -> list[Path]:
    """The JSON configs of the trained policies for (env id, task) in ``directory``, sorted."""
    configs = []
    for path in sorted(Path(directory).glob("*.json")):
        config = json.loads(path.read_text())
        if (config.get("env_id") == env_id and config.get("task") == task
                and path.with_suffix(".zip").exists()):
            configs.append(path)
    return configs


def load_policy(config_path: Path) -> tuple[Callable[[], Policy], dict[str, Any], dict[str, Any]]:
    """A trained policy (deterministic ``predict``), its ``gym.make`` arguments and its config."""
    from baselines.train import algorithm_class

    config = json.loads(Path(config_path).read_text())
    model = algorithm_class(config["algo"]).load(Path(config_path).with_suffix(".zip"),
                                                 device="cpu")  # fmt: skip

    def act(obs: Any) -> Any:
        return model.predict(obs, deterministic=True)[0]

    return (lambda: act), dict(config["env_kwargs"]), config


def summarize(episodes: Sequence[Episode], optimal_time: float, optimal_effort: float
              ) -> dict[str, Any]:  # fmt: skip
    """Success rate and, over the successes, time and effort as ratios to the optimum.

    Returns:
        {"episodes", "success_rate", "time_ratio" (mean), "time_ratio_median",
        "effort_ratio" (mean), "mean_time" [s], "mean_effort" [N^2 m^2 s],
        "solver_failures"}; the ratios are None without a success.
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
    }


def evaluate_controller(env_id: str, make_policy: Callable[[], Policy], env_kwargs: dict[str, Any],
                        seeds: Sequence[int]) -> tuple[Episode, list[Episode]]:  # fmt: skip
    """The nominal episode (no start noise, seed 0) and one perturbed episode per seed."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nominal = play(env_id, make_policy, 0, False, **env_kwargs)
        perturbed = [play(env_id, make_policy, int(seed), True, **env_kwargs) for seed in seeds]
    return nominal, perturbed


def compare(
    env_id: str,
    task: str,
    num_seeds: int = 20,
    policies: Sequence[Path] | None = None,
    extra_controllers: dict[str, tuple[Callable[[], Policy], dict[str, Any]]] | None = None,
    log: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Evaluate the optimal reference and the policies of (env id, task) on the same seeds.

    Args:
        env_id: a mission environment id. task: "time" or "effort".
        num_seeds: perturbed starts per controller (seeds 0 ... num_seeds - 1).
        policies: trained-policy JSON configs (default: ``shipped_policies(env_id, task)``).
        extra_controllers: more controllers, label -> (policy factory, ``gym.make`` arguments)
            (tests use the random policy and the reference's own controls).
        log: progress lines (default: none).

    Returns:
        {"env_id", "task", "reference", "optimal_time" [s], "optimal_effort" [N^2 m^2 s],
        "seeds", "controllers": [{"label", "algo", "config", "summary", "nominal",
        "episodes"}]}, the episodes as ``Episode`` objects (``write_comparison`` turns them
        into JSON).
    """
    if (env_id, task) not in REFERENCE_NAMES:
        known = ", ".join(f"{e} {t}" for e, t in REFERENCE_NAMES)
        raise ValueError(f"no optimal reference for {env_id} task {task!r}; known: {known}")
    say = log or (lambda _: None)
    reference = load_reference(REFERENCE_NAMES[(env_id, task)])
    optimal_time, optimal_effort = reference.final_time, reference_effort(reference)
    seeds = list(range(num_seeds))
    controllers: list[tuple[str, str, dict[str, Any], Callable[[], Policy], dict[str, Any]]] = []
    factory, options = reference_controller(reference)
    controllers.append((OPTIMAL, "optimal", {}, factory, options))
    for path in shipped_policies(env_id, task) if policies is None else policies:
        factory, options, config = load_policy(path)
        controllers.append((config["algo"], config["algo"], config, factory, options))
    for label, (factory, options) in (extra_controllers or {}).items():
        controllers.append((label, label, {}, factory, options))
    results = []
    for label, algo, config, factory, options in controllers:
        say(f"{env_id} {task}: {label}, nominal start + {num_seeds} perturbed starts")
        nominal, episodes = evaluate_controller(env_id, factory, options, seeds)
        summary = summarize(episodes, optimal_time, optimal_effort)
        results.append({"label": label, "algo": algo, "config": config, "summary": summary,
                        "nominal": nominal, "episodes": episodes})  # fmt: skip
    return {"env_id": env_id, "task": task, "reference": reference.name,
            "optimal_time": optimal_time, "optimal_effort": optimal_effort, "seeds": seeds,
            "controllers": results}  # fmt: skip


def budget_text(config: dict[str, Any]) -> str:
    """A policy's training budget, e.g. "10^7 steps, 64 envs, seed 0" ("" for the optimum)."""
    if not config:
        return ""
    steps = int(config.get("num_timesteps", config.get("total_timesteps", 0)))
    return f"{steps:.2g} steps, {config.get('num_envs')} envs, seed {config.get('seed')}"


def _ratio(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def markdown_table(comparisons: Sequence[dict[str, Any]]) -> str:
    """One row per env x task x controller: success, ratios to the optimum, nominal run."""
    lines = ["| env | task | controller | success (perturbed starts) | time / optimal | "
             "effort / optimal | nominal start | training budget |",
             "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for comparison in comparisons:
        env = comparison["env_id"].split("/")[-1]
        for row in comparison["controllers"]:
            s, nominal = row["summary"], row["nominal"]
            nominal_text = (f"success, {nominal.elapsed_time:.2f} s, effort {nominal.effort:.3g}"
                            if nominal.is_success else "fails")  # fmt: skip
            lines.append(
                f"| {env} | {comparison['task']} | {row['label']} | "
                f"{s['success_rate']:.0%} of {s['episodes']} | {_ratio(s['time_ratio'])} | "
                f"{_ratio(s['effort_ratio'])} | {nominal_text} | {budget_text(row['config'])} |"
            )
    return "\n".join(lines)


def comparison_record(comparison: dict[str, Any]) -> dict[str, Any]:
    """The comparison as plain JSON (episodes as their scores, no trajectories)."""
    record = {k: v for k, v in comparison.items() if k != "controllers"}
    record["controllers"] = [
        {"label": row["label"], "algo": row["algo"], "config": row["config"],
         "summary": row["summary"], "nominal": row["nominal"].scores(),
         "episodes": [e.scores() for e in row["episodes"]]}
        for row in comparison["controllers"]
    ]  # fmt: skip
    return record


def write_comparison(comparison: dict[str, Any], output: Path) -> list[Path]:
    """Write ``compare_{env}_{task}.json`` and ``.png`` into ``output``; returns their paths."""
    from baselines.compare_plots import plot_comparison

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    stem = f"compare_{comparison['env_id'].split('/')[-1]}_{comparison['task']}"
    json_path = output / f"{stem}.json"
    json_path.write_text(json.dumps(comparison_record(comparison), indent=1, default=str) + "\n")
    png_path = output / f"{stem}.png"
    plot_comparison(comparison, png_path)
    return [json_path, png_path]


__all__ = [
    "OPTIMAL", "REFERENCE_NAMES", "TASKS", "TRAINED_DIR", "Episode",
    "compare", "comparison_record", "evaluate_controller", "load_policy", "markdown_table",
    "play", "reference_controller", "reference_effort", "shipped_policies", "summarize",
    "write_comparison",
]
