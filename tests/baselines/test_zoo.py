"""rl-zoo3 reads the shipped hyperparameter files as ``mdi-envs train`` does, trains and plays."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest
import yaml

import mdi_envs  # noqa: F401 - registers the ids
from baselines.hyperparameters import (
    get_hyperparameters,
    hyperparameter_file,
    hyperparameter_table,
)

pytest.importorskip("rl_zoo3", reason="rl-zoo3 is in the rl extra")
MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
ZOO_ALGOS = {"PPO": "ppo", "SAC": "sac", "TQC": "tqc", "CrossQ": "crossq",
             "HybridPPO": "hybridppo"}


@pytest.mark.parametrize("key", sorted(hyperparameter_table()), ids=" ".join)
def test_rl_zoo3_resolves_our_entry(key: tuple[str, str, str]) -> None:
    """rl-zoo3's own reader finds the env id's entry (not its "default") with our values."""
    from rl_zoo3.exp_manager import ExperimentManager

    from baselines.train import with_schedules

    env_id, objective, algo = key
    entry = get_hyperparameters(env_id, algo, objective)
    manager = ExperimentManager(argparse.Namespace(), ZOO_ALGOS[algo], env_id, "unused",
                                config=str(hyperparameter_file(algo, objective)))  # fmt: skip
    hyperparams, _ = manager.read_hyperparameters()
    model_kwargs, *_ = manager._preprocess_hyperparams(dict(hyperparams))
    assert manager.n_envs == entry["num_envs"]
    assert manager.n_timesteps == entry["total_timesteps"]
    assert manager.env_kwargs == entry["env_kwargs"]
    assert manager.normalize == entry["normalize_reward"]
    if entry["normalize_reward"]:
        assert manager.normalize_kwargs == {"norm_obs": False, "norm_reward": True,
                                            "gamma": entry["algo_kwargs"]["gamma"]}  # fmt: skip
    assert model_kwargs.pop("policy") == "MlpPolicy"
    assert set(model_kwargs) == set(entry["algo_kwargs"])
    ours = with_schedules(entry["algo_kwargs"])
    for remaining in (1.0, 0.25):  # rl-zoo3 makes every rate a schedule; ours keeps numbers
        for key, value in model_kwargs.items():
            theirs, mine = (v(remaining) if callable(v) else v for v in (value, ours[key]))
            assert theirs == (pytest.approx(mine, rel=1e-12) if isinstance(mine, float)
                              else mine), key


@pytest.mark.slow
def test_rl_zoo3_train_uses_our_settings_and_enjoy_plays(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The README's command, ``-n 2000`` (one 64 x 256 rollout), then ``rl_zoo3.enjoy``.

    Both run in this process: ``python -m rl_zoo3.train ARGS`` is ``rl_zoo3.train.train()``
    with ``sys.argv = ["rl_zoo3/train.py", *ARGS]``.
    """
    from rl_zoo3.enjoy import enjoy
    from rl_zoo3.train import train

    conf = hyperparameter_file("PPO")
    common = ["--algo", "ppo", "--env", MANIPULATOR, "--gym-packages", "mdi_envs",
              "-f", str(tmp_path)]  # fmt: skip
    monkeypatch.setattr(sys, "argv", ["rl_zoo3/train.py", *common, "-conf", str(conf),
                                      "-n", "2000", "--seed", "0", "--num-threads", "1"])
    train()
    run = tmp_path / "ppo" / "mdi_envs-BlockableManipulator-v0_1"
    saved = yaml.unsafe_load((run / "mdi_envs-BlockableManipulator-v0" / "config.yml").read_text())
    zoo = yaml.safe_load(conf.read_text())[MANIPULATOR]
    assert dict(saved) == zoo  # rl-zoo3's record of the settings it trained with
    assert (run / "mdi_envs-BlockableManipulator-v0.zip").exists()
    capsys.readouterr()
    monkeypatch.setattr(sys, "argv", ["rl_zoo3/enjoy.py", *common, "-n", "600", "--no-render",
                                      "--deterministic"])
    enjoy()
    assert "Episode Length 500" in capsys.readouterr().out  # the untrained arm times out


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Training and eval env are not of the same type")
def test_hybrid_ppo_through_the_zoo_launcher(tmp_path: Path) -> None:
    """``python -m baselines.zoo train --algo hybridppo`` (shrunk rollout) and ``enjoy``."""
    from baselines.zoo import main

    common = ["--algo", "hybridppo", "--env", MANIPULATOR, "--gym-packages", "mdi_envs",
              "-f", str(tmp_path)]  # fmt: skip
    main(["train", *common, "-conf", str(hyperparameter_file("HybridPPO")), "-n", "256",
          "--seed", "0", "--eval-freq", "128", "--eval-episodes", "1",  # evaluates once
          "-params", "n_envs:2", "n_steps:64", "batch_size:64", "n_epochs:1"])
    assert (tmp_path / "hybridppo" / "mdi_envs-BlockableManipulator-v0_1"
            / "mdi_envs-BlockableManipulator-v0.zip").exists()  # fmt: skip
    main(["enjoy", *common, "-n", "50", "--no-render"])
    with pytest.raises(SystemExit, match="usage"):
        main(["play"])


def test_the_launcher_gives_rl_zoo3_the_entry_env_kwargs_for_evaluation() -> None:
    from baselines.zoo import eval_env_arguments

    conf = str(hyperparameter_file("PPO", "effort"))
    args = ["--algo", "ppo", "--env", "mdi_envs/DiffDriveRobot-v0", "-conf", conf]
    extra = eval_env_arguments(args)
    assert extra == ["--eval-env-kwargs", "objective:'effort'", "goal_weight:1000.0",
                     "shaping_discount:1.0"]  # fmt: skip
    assert {k: eval(v) for k, v in (a.split(":", 1) for a in extra[1:])} == get_hyperparameters(
        "mdi_envs/DiffDriveRobot-v0", "PPO", "effort")["env_kwargs"]  # rl-zoo3 evals each value
    assert eval_env_arguments([*args, "--eval-env-kwargs", "objective:'time'"]) == []
    assert eval_env_arguments(["--env", "mdi_envs/DiffDriveRobot-v0"]) == []
