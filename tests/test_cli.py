"""Tests of the ``mdi-envs`` command line (``mdi_envs/cli.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

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
    for name in ("lcp_methods_time.png", "lcp_complementarity.png",
                 "manipulator_brake_schedule.png"):
        assert (tmp_path / name).stat().st_size > 1000


def test_solve_reads_a_siconos_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # n = 2, dense storage (column-major), M = [[2, 1], [1, 2]], q = (-5, -6).
    path = tmp_path / "deudeu.dat"
    path.write_text("2\n0\n2\n2\n2 2\n2 1\n1 2\n-5 -6\n")
    assert main(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    assert "status CONVERGED" in out
    assert "1.333333" in out and "2.333333" in out


def test_solve_reports_a_ray_with_exit_code(tmp_path: Path) -> None:
    # w = -z - 1 < 0 for every z >= 0: infeasible, Lemke leaves on a ray.
    path = tmp_path / "infeasible.dat"
    path.write_text("2\n0\n2\n2\n2 2\n-1 0\n0 -1\n-1 -1\n")
    assert main(["solve", str(path)]) == 1
