"""Training smoke runs (<= 1000 steps) through ``train`` and the ``train`` subcommand."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from baselines.cli import add_train_parser
from baselines.hyperparameters import get_hyperparameters
from baselines.plots import plot_training
from baselines.train import load_trained, run_name

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
TINY = {"policy_kwargs": {"net_arch": [16, 16]}}


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    import torch

    torch.set_num_threads(1)


def _check_outputs(model_path: Path, algo: str, num_timesteps: int) -> dict:
    for suffix in (".zip", ".json", ".png"):
        assert model_path.with_suffix(suffix).stat().st_size > 0
    config = json.loads(model_path.with_suffix(".json").read_text())
    assert config["algo"] == algo and config["seed"] == 3
    assert config["num_timesteps"] >= num_timesteps
    assert config["env_kwargs"] == get_hyperparameters(MANIPULATOR, algo)["env_kwargs"]
    assert config["algo_kwargs"]["policy_kwargs"] == TINY["policy_kwargs"]  # not SB3's copy
    assert {"stable_baselines3", "torch", "gymnasium", "mdi_envs"} <= set(config["versions"])
    assert config["num_episodes"] >= 1  # 500-step manipulator episodes end within the budget
    assert np.isfinite(config["evaluation"]["mean_return"])
    assert (model_path.parent / "tensorboard").is_dir()
    rows = model_path.with_name(model_path.stem + "_episodes.csv").read_text().splitlines()
    assert rows[0].startswith("timesteps,return") and len(rows) == config["num_episodes"] + 1
    return config


@pytest.mark.slow
def test_train_ppo_smoke_with_normalized_rewards(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    from stable_baselines3 import PPO

    import baselines.hyperparameters as table
    from baselines.train import train

    monkeypatch.setitem(table.hyperparameter_table()[(MANIPULATOR, "time", "PPO")],
                        "normalize_reward", True)  # fmt: skip
    overrides = {"n_steps": 64, "batch_size": 64, "n_epochs": 2, **TINY}
    path = train(MANIPULATOR, "ppo", seed=3, total_timesteps=1000, output=tmp_path,
                 num_envs=2, algo_overrides=overrides, eval_episodes=1, progress_bar=False)
    assert path == tmp_path / f"{run_name(MANIPULATOR, 'time', 'PPO', 3)}.zip"
    config = _check_outputs(path, "PPO", 1000)
    assert config["normalize_reward"] is True
    # VecMonitor sits below VecNormalize: the logged returns are the env's own
    assert np.isfinite(config["train_last100"]["mean_return"])
    model = PPO.load(path, device="cpu")
    action, _ = model.predict(np.zeros(model.observation_space.shape, np.float32),
                              deterministic=True)  # fmt: skip
    assert model.action_space.contains(action)


@pytest.mark.slow
def test_train_sac_smoke_through_the_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    import baselines.hyperparameters as table

    entry = table.hyperparameter_table()[(MANIPULATOR, "time", "SAC")]
    monkeypatch.setitem(entry, "algo_kwargs", {**entry["algo_kwargs"], "learning_starts": 200,
                                               "batch_size": 32, "gradient_steps": 1,
                                               "buffer_size": 2000, **TINY})  # fmt: skip
    parser = argparse.ArgumentParser()
    add_train_parser(parser.add_subparsers())
    args = parser.parse_args(["train", MANIPULATOR, "sac", "--seed", "3", "--timesteps",
                              "1000", "--num-envs", "1", "--eval-episodes", "1",
                              "--output", str(tmp_path), "--no-progress-bar"])  # fmt: skip
    assert args.handler(args) == 0
    out = capsys.readouterr().out
    assert "trained SAC" in out and "evaluation (1 episodes" in out
    config = _check_outputs(tmp_path / f"{run_name(MANIPULATOR, 'time', 'SAC', 3)}.zip",
                            "SAC", 1000)  # fmt: skip
    assert config["num_envs"] == 1 and config["num_episodes"] == 2


def test_load_trained_keeps_n_step_returns_without_the_false_warning(tmp_path: Path) -> None:
    import warnings

    from stable_baselines3 import SAC

    SAC("MlpPolicy", "Pendulum-v1", n_steps=3, buffer_size=100, device="cpu").save(
        tmp_path / "sac")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning left on load fails the test
        model = load_trained("sac", tmp_path / "sac.zip")
    assert model.n_steps == 3
    assert model.replay_buffer.n_steps == 3 and model.replay_buffer.gamma == model.gamma


def test_cli_rejects_unknown_combinations() -> None:
    parser = argparse.ArgumentParser()
    add_train_parser(parser.add_subparsers())
    with pytest.raises(SystemExit):
        parser.parse_args(["train", "mdi_envs/BouncingBall-v0", "PPO"])
    args = parser.parse_args(["train", MANIPULATOR, "ppo"])
    assert args.algo == "PPO" and args.objective is None and args.seed is None


def test_plot_training_handles_empty_and_full_logs(tmp_path: Path) -> None:
    plot_training([], tmp_path / "empty.png")
    rows = [(100 * k, -float(k), 50, k % 2 == 0, 1.0, 2.0) for k in range(150)]
    plot_training(rows, tmp_path / "full.png", title="t")
    assert (tmp_path / "empty.png").stat().st_size > 0 and (tmp_path / "full.png").exists()


def test_every_shipped_training_record_reads_back(tmp_path: Path) -> None:
    from pydantic import ValidationError

    from baselines.evaluation import TRAINED_DIR
    from baselines.train import read_training

    paths = sorted(TRAINED_DIR.glob("*.json"))
    records = [read_training(path) for path in paths]
    assert records and all(r.commit and r.evaluation.episodes > 0 for r in records)
    broken = json.loads(paths[0].read_text())
    del broken["evaluation"]["seed"]
    (tmp_path / "broken.json").write_text(json.dumps(broken))
    with pytest.raises(ValidationError, match="evaluation.seed"):
        read_training(tmp_path / "broken.json")


def test_schedule_strings_are_read_as_rl_zoo3_reads_them() -> None:
    from baselines.hyperparameters import parse_schedule
    from baselines.train import with_schedules

    assert parse_schedule("learning_rate", 3e-4) == (3e-4, False)
    assert parse_schedule("learning_rate", "lin_0.002") == (0.002, True)
    resolved = with_schedules({"learning_rate": "lin_0.002", "clip_range": 0.2, "gamma": 0.99})
    assert [resolved["learning_rate"](remaining) for remaining in (1.0, 0.5, 0.0)] == pytest.approx(
        [0.002, 0.001, 0.0])
    assert resolved["clip_range"] == 0.2 and resolved["gamma"] == 0.99
    for bad in ("exp_0.002", "lin_fast"):
        with pytest.raises(ValueError, match="learning_rate: .* write lin_<initial value>"):
            with_schedules({"learning_rate": bad})
