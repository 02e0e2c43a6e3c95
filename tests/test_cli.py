"""Tests of the ``mdi-envs`` command line: the core subcommands and the plug-in mechanism."""

from __future__ import annotations

import argparse
import subprocess
import sys
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest
from peer_data import peer_params

from mdi_envs import cli
from mdi_envs.cli import COMMAND_GROUP, _build_parser, main, plugin_commands


def test_help_lists_every_plugin_without_importing_one() -> None:
    code = ("import sys\nfrom mdi_envs.cli import main\ntry:\n    main(['--help'])\n"
            "except SystemExit:\n    pass\nloaded = sorted({name.partition('.')[0] for name in "
            "sys.modules} & {'optimal', 'baselines', 'benchmarks'})\nprint('loaded', loaded)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    assert out.splitlines()[-1] == "loaded []"
    for name in (*plugin_commands(), "solve", "compile"):
        assert f"    {name} " in out


def test_no_command_prints_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 0
    assert "usage: mdi-envs" in capsys.readouterr().out


def test_every_registered_plugin_adds_its_subcommand() -> None:
    plugins = plugin_commands()
    assert {"optimize", "simulate", "demo", "train", "sweep", "compare", "bench"} <= set(plugins)
    for name in plugins:
        parser = _build_parser(name)
        subcommands = next(action for action in parser._actions
                           if isinstance(action, argparse._SubParsersAction))
        assert callable(subcommands.choices[name].get_default("handler")), name


@pytest.mark.parametrize(("value", "message"), [
    ("no_such_module_xyz:add", "its plug-in no_such_module_xyz:add cannot be imported"),
    ("argparse:ArgumentParser", "did not add a subcommand named 'broken'"),
])
def test_a_broken_plugin_is_reported(monkeypatch: pytest.MonkeyPatch, value: str,
                                     message: str) -> None:
    broken = EntryPoint(name="broken", value=value, group=COMMAND_GROUP)
    monkeypatch.setattr(cli, "entry_points", lambda group: [broken])
    with pytest.raises((SystemExit, RuntimeError, TypeError), match=message):
        main(["broken"])


def test_a_plugin_named_like_a_core_command_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    clash = EntryPoint(name="solve", value="optimal.cli:add_optimize_parser", group=COMMAND_GROUP)
    monkeypatch.setattr(cli, "entry_points", lambda group: [clash])
    with pytest.raises(RuntimeError, match="named like the core subcommand 'solve'"):
        main(["--help"])


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


def test_compile_runs_the_stages_asked_for_in_order() -> None:
    from mdi_envs.precompile import MAKE_STAGES, compile_env

    reported: list[str] = []
    compile_env("mdi_envs/SlidingBlock-v0", lambda stage, seconds: reported.append(stage),
                MAKE_STAGES)
    assert reported == ["env", "variants"]


def test_compile_refuses_an_unknown_stage_or_id(capsys: pytest.CaptureFixture[str]) -> None:
    from mdi_envs.precompile import compile_env, compile_envs

    with pytest.raises(ValueError, match=r"unknown stage\(s\) \['gpu'\]"):
        compile_envs(["mdi_envs/SlidingBlock-v0"], stages=("env", "gpu"), progress=False)
    with pytest.raises(ValueError, match="unknown env id 'mdi_envs/Nothing-v0'"):
        compile_env("mdi_envs/Nothing-v0")
    assert main(["compile", "mdi_envs/Nothing-v0", "--make-only"]) == 2
    assert "unknown env id(s) ['mdi_envs/Nothing-v0']" in capsys.readouterr().err
