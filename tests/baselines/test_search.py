"""``baselines.search``: the score's order, the evaluation, a study, the rl-zoo3 entry.

The evaluation against single-env episodes from the same starts; a study resumed by a second
worker session, with its trials' records; the best arguments written into an rl-zoo3 file.
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import yaml

from baselines import search
from baselines.hyperparameters import HYPERPARAMS_DIR


def test_score_ranks_success_then_ratio_then_closeness() -> None:
    step = 1.0 / search.NUM_STARTS
    ranked = [
        search.score(0.0, None, 3.0),
        search.score(0.0, None, 0.5),
        search.score(step, 5.0, 0.2),
        search.score(step, 1.0, 0.2),
        search.score(2 * step, 9.0, 0.3),  # one more success outweighs any ratio >= 0.8
        search.score(1.0, 1.4, 0.0),
        search.score(1.0, 0.8, 0.0),
    ]
    assert ranked == sorted(ranked) and len(set(ranked)) == len(ranked)
    assert search.score(2 * step, 100.0, 0.0) > search.score(step, 0.8, 0.0)
    assert -1.0 < search.score(0.0, None, 1e9) < search.score(0.0, None, 0.0) == 0.0
    with pytest.raises(ValueError, match="positive ratio"):
        search.score(0.5, None, 0.0)


class Constant:
    """A policy that always plays the same action (SB3's ``predict`` signature)."""

    def __init__(self, action: Any) -> None:
        self.action = np.asarray(action, np.float32)

    def predict(self, obs: Any, deterministic: bool = True) -> tuple[Any, None]:
        return np.tile(self.action, (len(obs), 1)), None


def test_evaluation_matches_single_env_episodes_from_the_same_starts() -> None:
    """The batched evaluation = one ``gym.make`` episode per start seed, played alone."""
    study = search.SEARCHES["DiffDriveRobotEffort-v1_ppo"]
    policy, num_starts = Constant([0.3, 0.35]), 3
    result = search.evaluate_starts(policy, study, optimum=10.0, num_starts=num_starts)
    distances, efforts = [], []
    for i in range(num_starts):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            env = gym.make(study.env_id, reset_noise_scale=search.START_NOISE)
        env.reset(seed=search.EVALUATION_SEED + i)
        done = False
        while not done:
            _, _, terminated, truncated, info = env.step(policy.action)
            done = terminated or truncated
        distances.append(info["distance_to_goal"])
        efforts.append(info["effort"])
    assert result["success_rate"] == 0.0 and result["ratio"] is None
    assert result["distance"] == pytest.approx(np.mean(distances), rel=1e-12)
    assert result["score"] == search.score(0.0, None, float(np.mean(distances)))
    assert len(set(np.round(distances, 9))) == num_starts  # the starts differ


SMALL_PPO = {"n_steps": 64, "batch_size": 512, "n_epochs": 5, "learning_rate": 3e-4,
             "gamma": 0.99, "gae_lambda": 0.95, "clip_range": 0.2, "ent_coef": 1e-6,
             "width": 64}  # fmt: skip


def test_study_resumes_records_its_trials_and_writes_the_best_into_yaml(tmp_path: Path) -> None:
    name = "DiffDriveRobot-v1_ppo"
    url = f"sqlite:///{tmp_path / 'studies.db'}"
    for n in (1, 2):  # a second worker session adds to the same study
        search.load_study(name, url).enqueue_trial({**SMALL_PPO, "learning_rate": 1e-4 * n})
        study = search.run(name, url, n_trials=1, timesteps=4096)
        assert len(study.trials) == n
    trial = study.trials[-1]
    assert trial.user_attrs["seed"] == 1 and "commit" in trial.user_attrs
    evaluations = [trial.user_attrs[f"evaluation_{k}"] for k in range(1, 5)]
    assert [e["timesteps"] for e in evaluations] == sorted(e["timesteps"] for e in evaluations)
    assert trial.value == evaluations[-1]["score"]
    assert trial.intermediate_values[4] == trial.value
    summary = search.summary(name, url)
    assert summary["trials"] == {"COMPLETE": 2} and summary["remaining"] == search.NUM_TRIALS - 2
    assert summary["cpu_hours"] == pytest.approx(
        sum(t.user_attrs["wall_time"] for t in study.trials) / 3600)
    best = search.best_arguments(name, url)
    assert best["policy_kwargs"] == {"net_arch": {"pi": [64, 64], "vf": [64, 64]}}

    shutil.copy(HYPERPARAMS_DIR / "ppo.yml", tmp_path / "ppo.yml")
    before = yaml.safe_load((tmp_path / "ppo.yml").read_text())
    path = search.write_yaml(name, url, directory=tmp_path)
    after = yaml.safe_load(path.read_text())
    entry = after["mdi_envs/DiffDriveRobot-v1"]
    assert entry["learning_rate"] == f"lin_{study.best_trial.params['learning_rate']}"
    assert entry["n_steps"] == 64 and entry["n_timesteps"] == 4_000_000
    assert {k: v for k, v in after.items() if k != "mdi_envs/DiffDriveRobot-v1"} == {
        k: v for k, v in before.items() if k != "mdi_envs/DiffDriveRobot-v1"}
    assert path.read_text().startswith("#")  # the file's comments stay


def test_reading_a_study_that_was_never_run_is_an_error_and_creates_nothing(
        tmp_path: Path) -> None:  # fmt: skip
    import optuna

    url = f"sqlite:///{tmp_path / 'studies.db'}"
    for read in (search.summary, search.best_arguments, search.plot):
        with pytest.raises(KeyError, match="is not in .* yet"):
            read("DiffDriveRobot-v1_sac", url)
    assert optuna.get_all_study_names(search.storage(url)) == []
    with pytest.raises(SystemExit, match="baselines.search run DiffDriveRobot-v1_sac"):
        search.main(["summary", "DiffDriveRobot-v1_sac", "--storage", url])
