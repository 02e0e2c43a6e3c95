"""The hyperparameter table (read from the rl-zoo3 YAML files): complete, consistent, shipped."""

from __future__ import annotations

import gymnasium as gym
import pytest

import mdi_envs  # noqa: F401 - registers the ids
from baselines.hyperparameters import (
    ALGORITHM_CLASSES,
    ALGORITHMS,
    DEFAULT_OBJECTIVES,
    HYPERPARAMS_DIR,
    canonical_algorithm,
    entry_from_zoo,
    get_hyperparameters,
    hyperparameter_file,
    hyperparameter_table,
)

HYPERPARAMETERS = hyperparameter_table()


def test_table_covers_both_envs_tasks_and_algorithms() -> None:
    assert len(HYPERPARAMETERS) == 20
    assert set(ALGORITHM_CLASSES) == {*ALGORITHMS, "DAgger", "DAgger+PPO"}
    for (env_id, objective, algo), entry in HYPERPARAMETERS.items():
        assert env_id in gym.registry and algo in ALGORITHMS and objective in ("time", "effort")
        assert {"num_envs", "total_timesteps", "seed", "algo_kwargs", "env_kwargs",
                "normalize_reward"} <= set(entry)
        assert isinstance(entry["normalize_reward"], bool)
        assert isinstance(entry["seed"], int) and entry["num_envs"] >= 1
        if env_id.endswith("-v0"):  # set by hand; a v1 entry's gamma may come from the search
            assert entry["algo_kwargs"]["gamma"] == 0.99
        else:
            assert entry["algo_kwargs"]["gamma"] in (0.98, 0.99, 0.995, 0.999)


def test_every_entry_fixes_the_shaping_discount_and_lookups_copy() -> None:
    for key, entry in HYPERPARAMETERS.items():
        expected = 0.99 if key == ("mdi_envs/BlockableManipulator-v0", "time", "PPO") else 1.0
        if key[0].endswith("-v1"):  # the id's default, the setting the v1 entries train with
            assert "shaping_discount" not in entry["env_kwargs"], key
        made = {**gym.spec(key[0]).kwargs, **entry["env_kwargs"]}
        assert made["shaping_discount"] == expected, key
    entry = get_hyperparameters("mdi_envs/DiffDriveRobot-v0", "sac", "effort")
    assert entry["env_kwargs"] == {"objective": "effort", "goal_weight": 1000.0,
                                   "shaping_discount": 1.0}  # fmt: skip
    entry["algo_kwargs"]["gamma"] = 0.5
    entry["env_kwargs"]["goal_weight"] = 1.0
    fresh = get_hyperparameters("mdi_envs/DiffDriveRobot-v0", "SAC", "effort")
    assert fresh["algo_kwargs"]["gamma"] == 0.99 and fresh["env_kwargs"]["goal_weight"] == 1000.0
    with pytest.raises(KeyError, match="known"):
        get_hyperparameters("mdi_envs/BlockableManipulator-v0", "PPO", "effort")


def test_every_id_of_the_table_trains_with_its_default_objective() -> None:
    assert set(DEFAULT_OBJECTIVES) == {env_id for env_id, _, _ in HYPERPARAMETERS}
    for (env_id, objective, algo), entry in HYPERPARAMETERS.items():
        if env_id.endswith("-v1"):  # one objective per v1 id: no objective needed
            assert objective == DEFAULT_OBJECTIVES[env_id]
            assert get_hyperparameters(env_id, algo) == entry
    with pytest.raises(KeyError, match="DiffDriveRobot-v1 effort PPO"):
        get_hyperparameters("mdi_envs/DiffDriveRobot-v1", "PPO", "effort")


def test_the_train_command_takes_every_id_of_the_table() -> None:
    import argparse

    from baselines.cli import add_train_parser

    parser = argparse.ArgumentParser()
    add_train_parser(parser.add_subparsers())
    for env_id in DEFAULT_OBJECTIVES:
        args = parser.parse_args(["train", env_id, "ppo"])
        assert (args.env_id, args.algo) == (env_id, "PPO")


def test_hybrid_ppo_uses_the_ppo_settings_on_the_hybrid_space() -> None:
    hybrid = get_hyperparameters("mdi_envs/BlockableManipulator-v0", "hybridppo")
    ppo = get_hyperparameters("mdi_envs/BlockableManipulator-v0", "ppo")
    assert hybrid["env_kwargs"] == {"action_mode": "hybrid", "shaping_discount": 1.0}
    same = ("num_envs", "seed", "algo_kwargs")  # the budgets differ (10^7 vs 5 x 10^6)
    assert {k: hybrid[k] for k in same} == {k: ppo[k] for k in same}
    assert [canonical_algorithm(a) for a in ("sac", "HYBRIDPPO", "dqn")] == [
        "SAC", "HybridPPO", "dqn"]
    with pytest.raises(KeyError, match="known"):
        get_hyperparameters("mdi_envs/DiffDriveRobot-v0", "HybridPPO")


def test_one_file_per_algorithm_and_task() -> None:
    files = {hyperparameter_file(algo, objective) for _, objective, algo in HYPERPARAMETERS}
    assert files == set(HYPERPARAMS_DIR.glob("*.yml"))
    assert hyperparameter_file("ppo", "effort").name == "ppo_effort.yml"
    assert hyperparameter_file("HybridPPO").name == "hybridppo.yml"


def test_entry_from_zoo_maps_rl_zoo3_keys_and_rejects_the_unsupported() -> None:
    zoo = {"n_envs": 8, "n_timesteps": 1e5, "policy": "MlpPolicy", "gamma": 0.9,
           "normalize": {"norm_obs": False, "norm_reward": True}, "env_kwargs": {"objective": "x"}}
    assert entry_from_zoo(zoo) == {"num_envs": 8, "total_timesteps": 100_000, "seed": 0,
                                   "algo_kwargs": {"gamma": 0.9}, "env_kwargs": {"objective": "x"},
                                   "normalize_reward": True}  # fmt: skip
    with pytest.raises(ValueError, match="MlpPolicy"):
        entry_from_zoo({**zoo, "policy": "CnnPolicy"})
    with pytest.raises(ValueError, match="normalize"):
        entry_from_zoo({**zoo, "normalize": True})


def test_shipped_policies_were_trained_with_the_table() -> None:
    """Every shipped policy's config (any seed) matches its entry (``mdi-envs train`` redoes it).

    The shipped configs are the values of the table the YAML files replaced: this pins them.
    """
    import json
    from pathlib import Path

    from baselines.evaluation import TRAINED_DIR

    configs = sorted(Path(TRAINED_DIR).glob("*.json"))
    assert configs, "no shipped policy"
    for path in configs:
        config = json.loads(path.read_text())
        entry = get_hyperparameters(config["env_id"], config["algo"], config["objective"])
        assert config["total_timesteps"] == entry["total_timesteps"], path.name
        assert config["num_envs"] == entry["num_envs"], path.name
        assert config["algo_kwargs"] == entry["algo_kwargs"], path.name
        assert config["env_kwargs"] == entry["env_kwargs"], path.name
        assert config.get("normalize_reward", False) == entry["normalize_reward"], path.name


@pytest.mark.parametrize("algo", ["TQC", "CrossQ"])
def test_the_off_policy_algorithms_share_sacs_settings(algo: str) -> None:
    """TQC and CrossQ: SAC's copies, budget, replay ratio, n-step returns and rewards."""
    objectives = [(env_id, objective) for env_id, objective, name in HYPERPARAMETERS
                  if name == algo]
    assert len(objectives) == 3  # the manipulator and both diff-drive objectives
    for env_id, objective in objectives:
        entry = get_hyperparameters(env_id, algo, objective)
        sac = get_hyperparameters(env_id, "SAC", objective)
        shared = ("train_freq", "gradient_steps", "learning_starts", "batch_size", "n_steps",
                  "gamma", "buffer_size", "ent_coef")
        assert (entry["num_envs"], entry["total_timesteps"]) == (sac["num_envs"],
                                                                 sac["total_timesteps"])
        assert [entry["algo_kwargs"][key] for key in shared] == [sac["algo_kwargs"][key]
                                                                 for key in shared]
        assert sac["algo_kwargs"]["n_steps"] == 10
        assert entry["env_kwargs"] == sac["env_kwargs"]
        assert entry["normalize_reward"] == sac["normalize_reward"] == (objective == "effort")
        if objective == "effort":  # PPO's effort reward
            ppo = get_hyperparameters(env_id, "PPO", objective)
            assert entry["env_kwargs"] == ppo["env_kwargs"]
