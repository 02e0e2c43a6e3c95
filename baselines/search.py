"""Hyperparameter search with Optuna around the batched training path.

One study per (v1 env id, algorithm) of ``SEARCHES``: PPO and SAC on the three tasks, HybridPPO
on the manipulator. A trial samples SB3 arguments (``sample_ppo``, ``sample_sac``), trains with
them on the batched env (``baselines.vec_env``; the table's env, copies and reward
normalization, ``baselines.hyperparameters``) for the search's trial budget, and is scored by
what the comparison tables report, not by the training return: the deterministic policy is
played from ``NUM_STARTS`` starts perturbed at ``START_NOISE`` (0.1 rad, rad/s, m, m/s), and

    score = success rate + 0.04 / max(ratio, 0.8)     if any start reaches the goal,
          = -d / (1 + d)                              otherwise,

with ratio the mean time (or effort) of the successful episodes over the optimal reference's
and d the mean distance to the goal (the env's ``distance_to_goal``) at the episodes' ends. A
success-rate step of 1/20 outweighs any ratio, so the score ranks by success first, then by the
ratio, and among policies that never succeed by how close they end. The same evaluation runs
``NUM_EVALUATIONS`` times during a trial; each is reported to Optuna, whose median pruner stops
a trial below the median of the earlier trials at the same evaluation.

Sampler: TPE (``optuna.samplers.TPESampler``, multivariate, the first 10 trials random). Each
trial trains from the seed ``trial.number``; every trial records its seed, the git commit, the
evaluations and its wall time as user attributes.

Storage: a study lives in an RDB storage, by default the committed SQLite file
``baselines/search/studies.db``. ``python -m baselines.search run STUDY`` adds trials to it and
resumes it; any number of workers may run it at once, against the SQLite file on one machine
or one shared database across machines (``--storage postgresql://...``); a trial whose worker
died is failed by its stopped heartbeat and enqueued again. ``plot STUDY`` writes the
optimization history, the fANOVA importances and the evaluations during each trial next to the
storage; ``write-yaml STUDY`` writes the best trial's arguments into the study's entry of the
rl-zoo3 file (``baselines/hyperparams``). ``baselines/search/README.md`` gives the commands and
each study's budget.
"""

from __future__ import annotations

import argparse
import json
import re
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

SEARCH_DIR = Path(__file__).parent / "search"
"""Where the committed study storage and its plots live."""

DEFAULT_STORAGE = f"sqlite:///{SEARCH_DIR / 'studies.db'}"
"""The RDB URL of the committed storage."""

START_NOISE = 0.1
"""Half-width of the start perturbation of the evaluation (``reset_noise_scale``)."""

NUM_STARTS = 20
"""Perturbed starts per evaluation (reset seeds ``EVALUATION_SEED + i``)."""

EVALUATION_SEED = 1_000_000
"""The first reset seed of the evaluation starts (apart from every training copy's seeds)."""

NUM_EVALUATIONS = 4
"""Evaluations per trial, evenly spaced over its budget (the last at its end)."""

NUM_TRIALS = 30
"""Finished (complete or pruned) trials per study: every worker stops there."""

RATIO_WEIGHT = 0.04
"""Weight of 1 / ratio in the score: below a success-rate step of 1 / NUM_STARTS for every
ratio >= 0.8."""


@dataclass(frozen=True)
class Search:
    """One study: an algorithm on a v1 env id, with its trial budget.

    Attributes:
        env_id: the v1 id.
        algo: "PPO", "SAC" or "HybridPPO".
        reference: the optimal reference of the maneuver (``optimal.load_reference``).
        timesteps: environment steps per trial.
        objective: "time" or "effort", the ratio of the score and the table's objective of
            the entry (its rl-zoo3 file).
        env_kwargs: ``gym.make`` arguments beyond the id.
    """

    env_id: str
    algo: str
    reference: str
    timesteps: int
    objective: str = "time"
    env_kwargs: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The study name, e.g. ``BlockableManipulator-v1_ppo``."""
        return f"{self.env_id.split('/')[-1]}_{self.algo.lower()}"


MANIPULATOR = "mdi_envs/BlockableManipulator-v1"
ROBOT = "mdi_envs/DiffDriveRobot-v1"
ROBOT_EFFORT = "mdi_envs/DiffDriveRobotEffort-v1"
_ON_POLICY_STEPS, _OFF_POLICY_STEPS = 500_000, 100_000
SEARCHES = {search.name: search for search in (
    Search(MANIPULATOR, "PPO", "manipulator_time", _ON_POLICY_STEPS),
    Search(MANIPULATOR, "HybridPPO", "manipulator_time", _ON_POLICY_STEPS,
           env_kwargs={"action_mode": "hybrid"}),
    Search(MANIPULATOR, "SAC", "manipulator_time", _OFF_POLICY_STEPS),
    Search(ROBOT, "PPO", "diff_drive_time", _ON_POLICY_STEPS),
    Search(ROBOT, "SAC", "diff_drive_time", _OFF_POLICY_STEPS),
    Search(ROBOT_EFFORT, "PPO", "diff_drive_effort", _ON_POLICY_STEPS, "effort"),
    Search(ROBOT_EFFORT, "SAC", "diff_drive_effort", _OFF_POLICY_STEPS, "effort"),
)}  # fmt: skip
"""The studies by name."""


# -- search spaces -------------------------------------------------------------------------
def sample_ppo(trial: Any) -> dict[str, Any]:
    """PPO (and HybridPPO) arguments for ``trial``; the table's 64 copies are kept.

    Rollouts of 64 x n_steps = 4096-32768 steps, minibatches 512-4096, 5-20 epochs, learning
    rate 1e-4-3e-3 (log), gamma, GAE lambda, clip range, entropy bonus 1e-8-1e-2 (log), and two
    hidden layers of 64-256 units for the policy and the value function.
    """
    width = trial.suggest_categorical("width", [64, 128, 256])
    return {
        "n_steps": trial.suggest_categorical("n_steps", [64, 128, 256, 512]),
        "batch_size": trial.suggest_categorical("batch_size", [512, 1024, 2048, 4096]),
        "n_epochs": trial.suggest_categorical("n_epochs", [5, 10, 20]),
        "learning_rate": trial.suggest_float("learning_rate", 1e-4, 3e-3, log=True),
        "gamma": trial.suggest_categorical("gamma", [0.98, 0.99, 0.995, 0.999]),
        "gae_lambda": trial.suggest_categorical("gae_lambda", [0.9, 0.95, 0.98]),
        "clip_range": trial.suggest_categorical("clip_range", [0.1, 0.2, 0.3]),
        "ent_coef": trial.suggest_float("ent_coef", 1e-8, 1e-2, log=True),
        "max_grad_norm": 0.5,
        "policy_kwargs": {"net_arch": {"pi": [width, width], "vf": [width, width]}},
    }


def sample_sac(trial: Any) -> dict[str, Any]:
    """SAC arguments for ``trial``; the table's 8 copies, buffer and entropy tuning are kept.

    Learning rate 1e-4-1e-3 (log), batch 128-512, gamma, Polyak tau, n-step returns 1-20,
    1-4 gradient steps per 8 transitions, 10^3-10^4 random warm-up steps, two hidden layers of
    128 or 256 units.
    """
    width = trial.suggest_categorical("width", [128, 256])
    return {
        "learning_rate": trial.suggest_float("learning_rate", 1e-4, 1e-3, log=True),
        "batch_size": trial.suggest_categorical("batch_size", [128, 256, 512]),
        "gamma": trial.suggest_categorical("gamma", [0.98, 0.99, 0.995]),
        "tau": trial.suggest_categorical("tau", [0.005, 0.01, 0.02]),
        "n_steps": trial.suggest_categorical("n_steps", [1, 3, 5, 10, 20]),
        "train_freq": 1,
        "gradient_steps": trial.suggest_categorical("gradient_steps", [1, 2, 4]),
        "learning_starts": trial.suggest_categorical("learning_starts", [1000, 5000, 10000]),
        "policy_kwargs": {"net_arch": [width, width]},
    }


SAMPLERS: dict[str, Callable[[Any], dict[str, Any]]] = {
    "PPO": sample_ppo, "HybridPPO": sample_ppo, "SAC": sample_sac,
}  # fmt: skip
"""Algorithm -> its search space."""


# -- the objective -------------------------------------------------------------------------
def score(success_rate: float, ratio: float | None, distance: float) -> float:
    """The trial score (module docstring): success first, then the ratio, else closeness.

    Args:
        success_rate: fraction of the starts that reached the goal, in [0, 1].
        ratio: mean time or effort of the successes over the optimum's (None without one).
        distance: mean ``distance_to_goal`` at the episodes' ends (>= 0).
    """
    if success_rate > 0.0:
        if ratio is None or not ratio > 0.0:
            raise ValueError(f"a success rate {success_rate} needs a positive ratio, got {ratio}")
        return success_rate + RATIO_WEIGHT / max(ratio, 0.8)
    return -distance / (1.0 + distance)


def optimal_cost(search: Search) -> float:
    """The reference's final time [s] ("time") or effort [N^2 m^2 s] ("effort")."""
    from optimal.references import load_reference

    reference = load_reference(search.reference)
    if search.objective == "time":
        return reference.final_time
    return float(np.sum(reference.tau**2) * reference.time_step)


def evaluate_starts(model: Any, search: Search, optimum: float, num_starts: int = NUM_STARTS,
                    noise: float = START_NOISE) -> dict[str, Any]:  # fmt: skip
    """Play the deterministic policy once from each of ``num_starts`` perturbed starts.

    All starts run side by side in one batched env (reset seeds ``EVALUATION_SEED + i``).

    Returns:
        {"success_rate", "ratio" (None without success), "distance", "score"}.
    """
    from baselines.vec_env import make_vec_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        venv = make_vec_env(search.env_id, num_starts, reset_noise_scale=noise,
                            **search.env_kwargs)  # fmt: skip
    venv.seed(EVALUATION_SEED)
    obs = venv.reset()
    finals: list[dict[str, Any] | None] = [None] * num_starts
    while any(final is None for final in finals):
        actions, _ = model.predict(obs, deterministic=True)
        obs, _, dones, infos = venv.step(actions)
        for i in np.flatnonzero(dones):
            if finals[i] is None:
                finals[i] = infos[i]
    venv.close()
    ends = [final for final in finals if final is not None]
    key = "elapsed_time" if search.objective == "time" else "effort"
    wins = [final[key] for final in ends if final["is_success"]]
    success_rate = len(wins) / num_starts
    ratio = float(np.mean(wins)) / optimum if wins else None
    distance = float(np.mean([final["distance_to_goal"] for final in ends]))
    return {"success_rate": success_rate, "ratio": ratio, "distance": distance,
            "score": score(success_rate, ratio, distance)}  # fmt: skip


def train_and_score(search: Search, algo_kwargs: dict[str, Any], seed: int,
                    report: Callable[[int, dict[str, Any]], bool] | None = None,
                    timesteps: int | None = None) -> dict[str, Any]:  # fmt: skip
    """Train with ``algo_kwargs`` on the table's env setup; evaluate ``NUM_EVALUATIONS`` times.

    Args:
        search: the study. algo_kwargs: SB3 arguments replacing the table's.
        seed: the training seed. timesteps: the budget (default ``search.timesteps``).
        report: called with (evaluation index from 1, evaluation) after each evaluation;
            returning True stops the training (a pruned trial).

    Returns:
        {"evaluations": [...], "stopped": bool, "timesteps", "wall_time" [s]}; the last
        evaluation is the trial's result.
    """
    import torch
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from baselines.hyperparameters import get_hyperparameters
    from baselines.train import algorithm_class
    from baselines.vec_env import make_vec_env

    torch.set_num_threads(1)
    entry = get_hyperparameters(search.env_id, search.algo, search.objective)
    kwargs = {**entry["algo_kwargs"], **algo_kwargs}
    total = search.timesteps if timesteps is None else int(timesteps)
    optimum = optimal_cost(search)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        venv: Any = VecMonitor(make_vec_env(search.env_id, entry["num_envs"],
                                            **entry["env_kwargs"]))  # fmt: skip
    if entry["normalize_reward"]:
        venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=kwargs["gamma"])
    model = algorithm_class(search.algo)("MlpPolicy", venv, seed=seed, device="cpu", **kwargs)
    evaluations: list[dict[str, Any]] = []
    marks = [round(total * (k + 1) / NUM_EVALUATIONS) for k in range(NUM_EVALUATIONS)]

    stopped = []

    class Evaluations(BaseCallback):
        def _on_step(self) -> bool:
            if len(evaluations) < len(marks) - 1 and self.num_timesteps >= marks[len(evaluations)]:
                evaluations.append({"timesteps": int(self.num_timesteps),
                                    **evaluate_starts(self.model, search, optimum)})
                if report is not None and report(len(evaluations), evaluations[-1]):
                    stopped.append(True)
                    return False
            return True

    start = time.perf_counter()
    model.learn(total_timesteps=total, callback=Evaluations())
    if not stopped:
        evaluations.append({"timesteps": int(model.num_timesteps),
                            **evaluate_starts(model, search, optimum)})
        if report is not None:
            report(len(evaluations), evaluations[-1])
    venv.close()
    return {"evaluations": evaluations, "stopped": bool(stopped),
            "timesteps": int(model.num_timesteps),
            "wall_time": time.perf_counter() - start}  # fmt: skip


# -- studies -------------------------------------------------------------------------------
def storage(url: str = DEFAULT_STORAGE) -> Any:
    """The RDB storage at ``url``, with heartbeats.

    A trial whose worker died is marked failed 10 min after its last heartbeat and enqueued
    again once (``RetryHeartbeatStaleTrialCallback``).
    """
    import optuna
    from sqlalchemy.exc import IntegrityError, OperationalError

    if url.startswith("sqlite:///"):
        Path(url.removeprefix("sqlite:///")).parent.mkdir(parents=True, exist_ok=True)

    def make() -> Any:
        with warnings.catch_warnings():  # heartbeats are marked experimental in Optuna
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            return optuna.storages.RDBStorage(
                url, heartbeat_interval=60, grace_period=600,
                heartbeat_stale_trial_callback=optuna.storages.RetryHeartbeatStaleTrialCallback(
                    max_retry=1))

    for attempt in range(2):  # workers started together race to create a new storage's tables
        try:
            return make()
        except (IntegrityError, OperationalError):
            time.sleep(1.0 + attempt)
    return make()


def load_study(name: str, url: str = DEFAULT_STORAGE, create: bool = True) -> Any:
    """The study ``name``: maximize the score, TPE sampler, median pruner.

    Raises:
        KeyError: an unknown name, or (``create`` False) a study not yet in the storage.
    """
    import optuna

    if name not in SEARCHES:
        raise KeyError(f"unknown study {name!r}; known: {', '.join(SEARCHES)}")
    rdb = storage(url)
    sampler = optuna.samplers.TPESampler(n_startup_trials=10, multivariate=True)
    pruner = optuna.pruners.MedianPruner(n_startup_trials=5, n_warmup_steps=1)
    if create:
        return optuna.create_study(study_name=name, storage=rdb, direction="maximize",
                                   load_if_exists=True, sampler=sampler, pruner=pruner)
    if name not in optuna.get_all_study_names(rdb):
        raise KeyError(f"study {name!r} is not in {url} yet; "
                       f"`python -m baselines.search run {name}` starts it")
    return optuna.load_study(study_name=name, storage=rdb, sampler=sampler, pruner=pruner)


def make_objective(search: Search, timesteps: int | None = None) -> Callable[[Any], float]:
    """The Optuna objective of ``search``: one training run, scored (module docstring).

    Every trial records the git commit of the tree at this call (the code the worker runs).
    """
    import optuna

    from mdi_envs.provenance import git_commit

    commit = git_commit()  # of the code this process imported

    def run(trial: Any) -> float:
        algo_kwargs = SAMPLERS[search.algo](trial)
        trial.set_user_attr("seed", trial.number)
        trial.set_user_attr("commit", commit)

        def report(index: int, evaluation: dict[str, Any]) -> bool:
            trial.report(evaluation["score"], index)
            trial.set_user_attr(f"evaluation_{index}", evaluation)
            return trial.should_prune()

        result = train_and_score(search, algo_kwargs, trial.number, report, timesteps)
        trial.set_user_attr("wall_time", result["wall_time"])
        trial.set_user_attr("timesteps", result["timesteps"])
        if result["stopped"]:
            raise optuna.TrialPruned()
        return float(result["evaluations"][-1]["score"])

    return run


def run(name: str, url: str = DEFAULT_STORAGE, n_trials: int | None = None,
        timeout: float | None = None, timesteps: int | None = None) -> Any:  # fmt: skip
    """Add trials to the study; returns it.

    Stops after ``n_trials`` trials, ``timeout`` seconds, or when the study holds
    ``NUM_TRIALS`` finished (complete or pruned) ones, whichever comes first.
    """
    import optuna

    study = load_study(name, url)
    finished = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
    study.optimize(make_objective(SEARCHES[name], timesteps), n_trials=n_trials, timeout=timeout,
                   callbacks=[optuna.study.MaxTrialsCallback(NUM_TRIALS, states=finished)],
                   gc_after_trial=True)  # fmt: skip
    return study


def plot(name: str, url: str = DEFAULT_STORAGE, output: Path = SEARCH_DIR) -> list[Path]:
    """Write the study's history, importance and intermediate-value plots; returns the paths.

    The importances need two finished trials and are skipped before.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import optuna
    from optuna.visualization import matplotlib as optuna_plots

    study = load_study(name, url, create=False)
    finished = study.get_trials(states=(optuna.trial.TrialState.COMPLETE,))
    plots = {"history": optuna_plots.plot_optimization_history,
             "intermediate": optuna_plots.plot_intermediate_values}
    if len(finished) >= 2:
        plots["importances"] = optuna_plots.plot_param_importances
    paths = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # optuna marks its matplotlib plots experimental
        for kind, draw in plots.items():
            axes = draw(study)
            axes.set_title(f"{name}: {axes.get_title()}")
            path = Path(output) / f"{name}_{kind}.png"
            axes.figure.set_size_inches(8, 5)
            axes.figure.tight_layout()
            axes.figure.savefig(path, dpi=100)
            plt.close(axes.figure)
            paths.append(path)
    return paths


def summary(name: str, url: str = DEFAULT_STORAGE) -> dict[str, Any]:
    """Trial counts by state, the compute spent and left, the best trial's score and arguments.

    "cpu_hours": the trials' recorded wall times summed (a trial trains on one core);
    "remaining": finished (complete or pruned) trials still to run up to ``NUM_TRIALS``.
    """
    import optuna

    study = load_study(name, url, create=False)
    counts: dict[str, int] = {}
    for trial in study.trials:
        counts[trial.state.name] = counts.get(trial.state.name, 0) + 1
    finished = counts.get("COMPLETE", 0) + counts.get("PRUNED", 0)
    result: dict[str, Any] = {
        "study": name, "trials": counts, "remaining": max(NUM_TRIALS - finished, 0),
        "cpu_hours": sum(t.user_attrs.get("wall_time", 0.0) for t in study.trials) / 3600}
    if study.get_trials(states=(optuna.trial.TrialState.COMPLETE,)):
        best = study.best_trial
        last = max(int(key.split("_")[1]) for key in best.user_attrs if
                   key.startswith("evaluation_"))  # fmt: skip
        result.update({"best_trial": best.number, "best_score": best.value,
                       "best_evaluation": best.user_attrs[f"evaluation_{last}"],
                       "best_params": best.params})  # fmt: skip
    return result


def best_arguments(name: str, url: str = DEFAULT_STORAGE) -> dict[str, Any]:
    """The SB3 arguments of the study's best finished trial."""
    import optuna

    study = load_study(name, url, create=False)
    return SAMPLERS[SEARCHES[name].algo](optuna.trial.FixedTrial(study.best_trial.params))


ANNEALED = ("PPO", "HybridPPO")
"""Algorithms whose searched learning rate is written as rl-zoo3's ``lin_X``, decaying linearly to
0 over the run's budget (8-20x a trial's): a trial ranks how fast a setting learns, and at a
constant rate a fast-learning setting can keep swinging between success and failure to the end
of a long run (docs/guide/baselines.md shows one)."""


def write_yaml(name: str, url: str = DEFAULT_STORAGE, directory: Path | None = None) -> Path:
    """Write the best trial's arguments into the study's entry of its rl-zoo3 file.

    The entry keeps its copies, budget, normalization and env arguments; the other entries
    and the file's comments are left as they are. For the algorithms of ``ANNEALED`` the
    searched learning rate is the start of rl-zoo3's linear schedule ``lin_X``. Returns the
    file's path.

    Raises:
        KeyError: the file has no entry for the study's env id.
    """
    import yaml

    from baselines.hyperparameters import HYPERPARAMS_DIR, hyperparameter_file

    search = SEARCHES[name]
    path = hyperparameter_file(search.algo, search.objective)
    if directory is not None:
        path = Path(directory) / path.name
    elif path.parent != HYPERPARAMS_DIR:
        raise ValueError(f"{path} is not in {HYPERPARAMS_DIR}")
    text = path.read_text()
    entries = yaml.safe_load(text)
    if search.env_id not in entries:
        raise KeyError(f"{path.name} has no entry {search.env_id}")
    entry = {**entries[search.env_id], **best_arguments(name, url)}
    if search.algo in ANNEALED:
        entry["learning_rate"] = f"lin_{entry['learning_rate']}"
    block = yaml.safe_dump({search.env_id: entry}, sort_keys=False, default_flow_style=None)
    pattern = re.compile(rf"^{re.escape(search.env_id)}:.*?(?=^\S|\Z)", re.M | re.S)
    path.write_text(pattern.sub(lambda _: block + "\n", text, count=1).rstrip("\n") + "\n")
    return path


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m baselines.search {run,plot,summary,write-yaml} STUDY [...]``."""
    parser = argparse.ArgumentParser(prog="python -m baselines.search", description=__doc__
                                     .split("\n")[0])  # fmt: skip
    parser.add_argument("command", choices=("run", "plot", "summary", "write-yaml"))
    parser.add_argument("study", choices=tuple(SEARCHES))
    parser.add_argument("--storage", default=DEFAULT_STORAGE, help="RDB URL of the studies")
    parser.add_argument("--n-trials", type=int, default=None, help="trials to add (run)")
    parser.add_argument("--timeout", type=float, default=None, help="seconds to run (run)")
    parser.add_argument("--timesteps", type=int, default=None,
                        help="steps per trial (run; default the study's budget)")
    args = parser.parse_args(argv)
    if args.command == "run":
        run(args.study, args.storage, args.n_trials, args.timeout, args.timesteps)
    try:
        if args.command == "plot":
            for path in plot(args.study, args.storage):
                print(path)
        if args.command == "write-yaml":
            print(write_yaml(args.study, args.storage))
        print(json.dumps(summary(args.study, args.storage), indent=2, default=str))
    except KeyError as error:
        raise SystemExit(f"baselines.search: {error.args[0]}") from error
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = [
    "ANNEALED", "DEFAULT_STORAGE", "NUM_STARTS", "SEARCHES", "START_NOISE", "Search",
    "best_arguments", "evaluate_starts", "load_study", "make_objective", "optimal_cost", "plot",
    "run", "sample_ppo", "sample_sac", "score", "summary", "train_and_score", "write_yaml",
]
