"""Tests of the ``mdi-envs`` command line (``mdi_envs/cli.py``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from peer_data import peer_params

from mdi_envs.cli import main


def test_help_lists_the_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    out = capsys.readouterr().out
    assert "demo" in out and "solve" in out


def test_no_command_prints_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 0
    assert "usage: mdi-envs" in capsys.readouterr().out


def test_demo_writes_its_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "CONVERGED" in out
    assert "max deviation from the event-driven reference" in out
    assert "optimal reference manipulator_time replayed" in out and "success True" in out
    assert "success False" not in out
    for name in ("lcp_methods_time.png", "lcp_complementarity.png",
                 "manipulator_brake_schedule.png", "manipulator_time.gif"):
        assert (tmp_path / name).stat().st_size > 1000


def test_solve_reads_a_siconos_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # n = 2, dense storage (column-major), M = [[2, 1], [1, 2]], q = (-5, -6).
    path = tmp_path / "deudeu.dat"
    path.write_text("2\n0\n2\n2\n2 2\n2 1\n1 2\n-5 -6\n")
    assert main(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    assert "status CONVERGED" in out
    assert "1.333333" in out and "2.333333" in out


@pytest.mark.parametrize("path", peer_params("fc2d", ["FC2D_SliderCrankLagrangian00000"])
                         + peer_params("fc3d", ["FC3D_Example1"]))
def test_solve_reads_a_friction_contact_file(path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["solve", "--problem", "friction", str(path)]) == 0
    out = capsys.readouterr().out
    assert "status CONVERGED" in out and "contacts of dimension" in out


def test_solve_reports_a_ray_with_exit_code(tmp_path: Path) -> None:
    # w = -z - 1 < 0 for every z >= 0: infeasible, Lemke leaves on a ray.
    path = tmp_path / "infeasible.dat"
    path.write_text("2\n0\n2\n2\n2 2\n-1 0\n0 -1\n-1 -1\n")
    assert main(["solve", str(path)]) == 1


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
