"""The seed x algorithm x objective grid of ``baselines.train`` (``mdi-envs sweep``, Ray Tune).

One Tune trial per (env id, objective, algorithm, seed) that the table has
(``baselines/hyperparams``) and whose ``STEM.json`` is not yet in ``output``: a finished run is
never rerun, so an interrupted sweep resumes by running the same command again, and runs made by
``mdi-envs train`` into the same folder count as finished. Each trial calls
``baselines.train.train`` in a Ray worker process (which imports ``mdi_envs`` and so registers the
env ids there) and writes the usual ``STEM.zip``, ``STEM.json``, ``STEM_episodes.csv``,
``STEM.png`` into ``output``, the folder ``mdi-envs compare --trained OUTPUT`` aggregates over
seeds. Tune's own records (trial logs, errors, the driver's experiment state) go to
``output/ray_results``.

Where it runs: without ``address`` a local Ray instance on this machine's cores
(``num_cpus``, default all), ``cpus_per_trial`` cores reserved per trial (one: torch runs on
one thread, so trials run side by side, one per core). With ``address`` (e.g.
``ray://head:10001`` or ``auto``) an existing cluster: every node needs the package installed
(``pip install 'mdi-envs[ray]'``) and ``output`` must be a path every node writes to and the
driver reads (a shared filesystem), since each trial writes its files where it runs.

Example (the plan's PPO/HybridPPO seeds, 16 runs of 10-80 min each on 2 cores)::

    mdi-envs sweep --algos PPO HybridPPO --seeds 0 1 2 3 4 --output results/sweep
    mdi-envs compare all --trained results/sweep
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from baselines.hyperparameters import canonical_algorithm, hyperparameter_table


@dataclass(frozen=True)
class Trial:
    """One run of the grid: ``train(env_id, algo, objective, seed)``."""

    env_id: str
    objective: str
    algo: str
    seed: int

    @property
    def stem(self) -> str:
        """The run's file stem (``baselines.train.run_name``)."""
        return f"{self.env_id.split('/')[-1]}_{self.objective}_{self.algo.lower()}_seed{self.seed}"


def grid(algos: Sequence[str], seeds: Sequence[int], env_ids: Sequence[str] | None = None,
         objectives: Sequence[str] | None = None) -> list[Trial]:  # fmt: skip
    """Every (env id, objective, algorithm) of the table matching the filters, times ``seeds``.

    Args:
        algos: algorithm names (case-insensitive). seeds: training seeds.
        env_ids, objectives: keep only these (None: all).
    """
    wanted = {canonical_algorithm(a) for a in algos}
    return [Trial(env_id, objective, algo, int(seed))
            for (env_id, objective, algo) in hyperparameter_table()
            if algo in wanted and (env_ids is None or env_id in env_ids)
            and (objectives is None or objective in objectives)
            for seed in seeds]  # fmt: skip


def is_finished(trial: Trial, output: Path) -> bool:
    """Whether ``output`` holds the trial's ``STEM.json`` (written last by ``train``)."""
    return (Path(output) / f"{trial.stem}.json").exists()


def run_trial(config: dict[str, Any]) -> dict[str, Any]:
    """Tune's function trainable: one ``train`` call; returns its scores as the final result.

    ``config["trial"]`` holds the ``Trial`` fields, ``config["train"]`` the keyword arguments of
    ``train`` shared by the grid (output, budget overrides, evaluation episodes).
    """
    from baselines.train import read_training, train

    trial, options = config["trial"], dict(config["train"])
    output = Path(options.pop("output"))
    path = train(trial["env_id"], trial["algo"], objective=trial["objective"], seed=trial["seed"],
                 output=output, progress_bar=False, **options)  # fmt: skip
    record = read_training(path.with_suffix(".json"))
    return {"stem": path.stem, "num_timesteps": record.num_timesteps,
            "wall_time_s": record.wall_time_s,
            "train_success_rate": record.train_last100.success_rate,
            "eval_success_rate": record.evaluation.success_rate,
            "eval_mean_return": record.evaluation.mean_return}  # fmt: skip


def sweep(
    trials: Sequence[Trial],
    output: Path,
    *,
    address: str | None = None,
    num_cpus: int | None = None,
    cpus_per_trial: float = 1.0,
    total_timesteps: int | None = None,
    num_envs: int | None = None,
    algo_overrides: dict[str, Any] | None = None,
    eval_episodes: int = 10,
    log: Callable[[str], None] | None = None,
) -> dict[str, list[str]]:
    """Run the unfinished ``trials`` through Ray Tune; returns the stems by outcome.

    Args:
        trials: the grid (``grid``). output: the shared results folder (created).
        address: an existing Ray cluster (None: start a local one, ``num_cpus`` cores).
        cpus_per_trial: cores Tune reserves per trial.
        total_timesteps, num_envs, algo_overrides, eval_episodes: passed to every ``train``.
        log: progress lines (default: none).

    Returns:
        {"skipped": already finished, "finished": run now, "failed": errored (Tune's error
        files under ``output/ray_results``)}.
    """
    say = log or (lambda _: None)
    output = Path(output).resolve()  # trials run in their own working directories
    output.mkdir(parents=True, exist_ok=True)
    skipped = [t.stem for t in trials if is_finished(t, output)]
    pending = [t for t in trials if not is_finished(t, output)]
    say(f"sweep: {len(pending)} to run, {len(skipped)} already in {output}")
    outcome: dict[str, list[str]] = {"skipped": skipped, "finished": [], "failed": []}
    if not pending:
        return outcome
    import ray
    from ray import tune

    common = {"output": str(output), "total_timesteps": total_timesteps, "num_envs": num_envs,
              "algo_overrides": algo_overrides, "eval_episodes": eval_episodes}  # fmt: skip
    ray.init(address=address, num_cpus=None if address else num_cpus,
             include_dashboard=False, ignore_reinit_error=True)  # fmt: skip
    try:
        tuner = tune.Tuner(
            tune.with_resources(run_trial, {"cpu": cpus_per_trial}),
            param_space={"trial": tune.grid_search([asdict(t) for t in pending]),
                         "train": common},
            tune_config=tune.TuneConfig(trial_name_creator=_trial_stem,
                                        trial_dirname_creator=_trial_stem),
            run_config=tune.RunConfig(name="sweep", storage_path=str(output / "ray_results"),
                                      failure_config=tune.FailureConfig(max_failures=0),
                                      verbose=0),
        )  # fmt: skip
        results = tuner.fit()
        for index in range(len(results)):  # a ResultGrid indexes, typed without __iter__
            result = results[index]
            trial, metrics = Trial(**(result.config or {})["trial"]), result.metrics or {}
            if result.error is not None or not is_finished(trial, output):
                outcome["failed"].append(trial.stem)
                say(f"{trial.stem}: failed ({type(result.error).__name__}: {result.error})")
            else:
                outcome["finished"].append(trial.stem)
                say(f"{trial.stem}: {metrics.get('num_timesteps')} steps, evaluation success "
                    f"{metrics.get('eval_success_rate')}")  # fmt: skip
    finally:
        ray.shutdown()
    return outcome


def _trial_stem(trial: Any) -> str:
    return Trial(**trial.config["trial"]).stem


__all__ = ["Trial", "grid", "is_finished", "run_trial", "sweep"]
