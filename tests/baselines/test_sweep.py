"""The Ray Tune sweep: the grid, resuming from finished runs, and a 2-trial smoke run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from baselines.sweep import Trial, grid, is_finished, sweep
from baselines.train import run_name

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
TINY = {"n_steps": 64, "batch_size": 64, "n_epochs": 1, "policy_kwargs": {"net_arch": [8, 8]}}


def test_grid_crosses_the_table_with_the_seeds() -> None:
    trials = grid(["ppo", "HybridPPO"], [0, 1])
    # PPO on three env x objectives, HybridPPO on the manipulator; the v0 and the v1 ids
    assert len(trials) == 2 * 4 * 2
    assert Trial("mdi_envs/DiffDriveRobot-v0", "effort", "PPO", 1) in trials
    assert all(t.stem == run_name(t.env_id, t.objective, t.algo, t.seed) for t in trials)
    assert grid(["SAC"], [3], env_ids=[MANIPULATOR]) == [Trial(MANIPULATOR, "time", "SAC", 3)]
    assert grid(["HybridPPO"], [0], objectives=["effort"]) == []


def test_dry_run_lists_finished_and_pending_runs(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    from mdi_envs.cli import main

    (tmp_path / "BlockableManipulator-v0_time_ppo_seed4.json").write_text("{}")
    assert is_finished(Trial(MANIPULATOR, "time", "PPO", 4), tmp_path)
    assert main(["sweep", "--algos", "PPO", "--env-ids", MANIPULATOR, "--seeds", "4", "5",
                 "--output", str(tmp_path), "--dry-run"]) == 0  # fmt: skip
    assert capsys.readouterr().out.splitlines() == [
        "BlockableManipulator-v0_time_ppo_seed4: finished",
        "BlockableManipulator-v0_time_ppo_seed5: to run"]
    assert sweep(grid(["PPO"], [4], env_ids=[MANIPULATOR]), tmp_path)["skipped"] == [
        "BlockableManipulator-v0_time_ppo_seed4"]  # nothing to run: Ray is not even started


@pytest.mark.slow
def test_tune_runs_two_trials_then_resumes_without_rerunning(tmp_path: Path) -> None:
    pytest.importorskip("ray.tune", reason="Ray Tune is in the ray extra "
                        "(pip install 'mdi-envs[ray]')")  # fmt: skip
    trials = grid(["PPO"], [0, 1], env_ids=[MANIPULATOR])
    options = {"num_cpus": 2, "total_timesteps": 256, "num_envs": 2, "algo_overrides": TINY,
               "eval_episodes": 1}  # fmt: skip
    outcome = sweep(trials, tmp_path, **options)
    assert outcome == {"skipped": [], "failed": [],
                       "finished": [t.stem for t in trials]}  # fmt: skip
    for trial in trials:
        config = json.loads((tmp_path / f"{trial.stem}.json").read_text())
        assert (config["seed"], config["num_timesteps"]) == (trial.seed, 256)
        assert (tmp_path / f"{trial.stem}.zip").exists()
    again = sweep(trials, tmp_path, **options)
    assert again == {"skipped": [t.stem for t in trials], "finished": [], "failed": []}
