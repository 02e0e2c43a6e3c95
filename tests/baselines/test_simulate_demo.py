"""``mdi-envs simulate`` and ``mdi-envs demo`` (the baselines' plug-in subcommands)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mdi_envs.cli import main


def test_simulate_replays_the_optimal_reference_to_success(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gif = tmp_path / "ref.gif"
    assert main(["simulate", "mdi_envs/BlockableManipulator-v0", "--policy",
                 "reference:manipulator_time", "--save", str(gif)]) == 0
    out = capsys.readouterr().out
    assert "(terminated)" in out and "success True" in out
    assert gif.stat().st_size > 0


def test_simulate_open_loop_file_and_env_args(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    actions = tmp_path / "actions.csv"
    np.savetxt(actions, np.tile([0.5, 0.5], (10, 1)), delimiter=",")
    assert main(["simulate", "mdi_envs/DiffDriveRobot-v0", "--policy", str(actions),
                 "--env-arg", "objective=effort", "--steps", "10"]) == 0
    out = capsys.readouterr().out
    assert "10 steps (stopped)" in out and "elapsed 0.500 s" in out
    with pytest.raises(ValueError, match=".npy or .csv"):
        main(["simulate", "mdi_envs/DiffDriveRobot-v0", "--policy", str(tmp_path / "a.txt")])


@pytest.mark.slow  # the whole demo: every reference and shipped policy, played and animated
def test_demo_shows_envs_references_and_the_comparison(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["demo", "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for env_id in ("mdi_envs/BlockableManipulator-v0", "mdi_envs/DiffDriveRobot-v0"):
        assert f"{env_id}\n  action space " in out
    for name in ("manipulator_time", "diff_drive_time", "diff_drive_effort"):
        line = next(line for line in out.splitlines() if line.startswith(f"{name} (mdi_envs/"))
        assert "success True" in line and (tmp_path / f"{name}.gif").stat().st_size > 1000
    rows = [line for line in out.splitlines() if line.startswith("| BlockableManipulator-v0 ")]
    for controller in ("optimal (open loop)", "MPC (shrinking horizon)", "HybridPPO"):
        assert any(f"| {controller} " in row for row in rows), controller
    assert "mdi_envs/BlockableManipulator-v0 (time) HybridPPO seed" in out
    assert "mdi_envs/DiffDriveRobot-v0 (effort) PPO seed" in out
    assert len(list(tmp_path.glob("*_seed*.gif"))) == 3
