"""The ``compare`` and ``robustness`` subcommands: files, tables, merges, shipped results."""

from __future__ import annotations

import argparse
import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from baselines.cli import add_compare_parser, add_robustness_parser
from baselines.evaluation import TRAINED_DIR
from baselines.heuristics import FOLLOWER
from baselines.model_based import LQR
from baselines.records import OPTIMAL, read_study, write_study
from baselines.tables import comparison_report, interval_text, robustness_table

ROBOT = "mdi_envs/DiffDriveRobot-v0"
MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
RESULTS = Path(TRAINED_DIR).parent


def run(*argv: str) -> int:
    """Parse ``argv`` with the baselines' study subcommands and run its handler."""
    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers()
    add_compare_parser(commands)
    add_robustness_parser(commands)
    args = parser.parse_args(argv)
    return int(args.handler(args))


@pytest.fixture()
def two_seeds(tmp_path: Path) -> Path:
    """Two shipped PPO policies of the robot's effort objective (81-step episodes)."""
    trained = tmp_path / "trained"
    trained.mkdir()
    for path in TRAINED_DIR.glob("DiffDriveRobot-v0_effort_ppo_seed[01]*"):
        shutil.copy(path, trained)
    return trained


def test_compare_plays_two_scales_and_merges_a_rerun(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    common = ["compare", ROBOT, "--objective", "effort", "--seeds", "1", "--trained",
              str(tmp_path), "--output", str(out)]  # fmt: skip
    assert run(*common, "--scales", "0.01", "0.1") == 0
    table = capsys.readouterr().out
    assert (out / "compare.md").read_text().strip() == table.strip()
    assert table.count(f"| {OPTIMAL} ") == 2  # one row per scale
    for name in ("compare_{}.png", "compare_{}_scale0.1.png", "seeds_{}.png", "compare_{}.md"):
        assert (out / name.format("DiffDriveRobot-v0_effort")).stat().st_size > 0, name
    path = out / "compare_DiffDriveRobot-v0_effort.json"
    study = read_study(path)
    assert [c.scale for c in study.conditions] == [0.01, 0.1]
    assert [row.label for row in study.rows] == [OPTIMAL, FOLLOWER, LQR]  # no trained policies
    optimal = study.row(OPTIMAL)
    assert [run.condition.scale for run in optimal.runs] == [0.01, 0.1]
    assert all(run.commit and run.nominal.trajectory for run in optimal.runs)
    # a row rerun merges: the others stay, and so does a trained row whose algorithm is
    # shipped (SAC in baselines/trained, not in --trained); one whose policies are gone is dropped
    kept = dataclasses.replace(optimal, label="kept row")
    shipped = dataclasses.replace(optimal, label="SAC", trained=True)
    withdrawn = dataclasses.replace(optimal, label="TQC", trained=True)
    write_study(dataclasses.replace(study, rows=[kept, optimal, shipped, withdrawn]), path)
    assert run(*common, "--scales", "0.3", "--controllers", OPTIMAL) == 0
    merged = read_study(path)
    assert [c.scale for c in merged.conditions] == [0.01, 0.1, 0.3]
    assert [row.label for row in merged.rows] == ["kept row", OPTIMAL, "SAC"]
    assert merged.rows[0] == kept and len(merged.row(OPTIMAL).runs) == 3
    assert "| kept row " in (out / "compare.md").read_text()
    with pytest.raises(SystemExit, match="no controller 'PP0'"):
        run(*common, "--controllers", "PP0")
    with pytest.raises(SystemExit, match="has no objective"):
        run("compare", MANIPULATOR, "--objective", "effort", "--output", str(out))


def test_compare_aggregates_shipped_seeds(two_seeds: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert run("compare", ROBOT, "--objective", "effort", "--seeds", "1", "--bootstrap-reps",
               "50", "--trained", str(two_seeds), "--output", str(out)) == 0
    table = (out / "compare.md").read_text()
    assert "2 seeds x 1 starts" in table and "(n=2" in table
    assert "5e+06 steps, 64 envs, seeds 0-1" in table
    ppo = read_study(out / "compare_DiffDriveRobot-v0_effort.json").row("PPO")
    assert [run.seed for run in ppo.runs] == [0, 1]
    assert all(run.commit and run.training.commit for run in ppo.runs)  # evaluated, trained at
    success = ppo.aggregate("perturbation 0.01").success_rate
    assert success.n == 2 and success.mean == np.mean([r.scores.success_rate for r in ppo.runs])
    assert (out / "seeds_DiffDriveRobot-v0_effort.png").stat().st_size > 10_000


def test_robustness_writes_json_plot_and_table(tmp_path: Path) -> None:
    from baselines.robustness import main

    out = tmp_path / "out"
    assert main([ROBOT, "--objective", "effort", "--seeds", "1", "--scales", "0.01",
                 "--trained", str(tmp_path), "--output", str(out)]) == 0
    study = read_study(out / "robustness_DiffDriveRobot-v0_effort.json")
    assert study.objective == "effort" and study.num_starts == 1 and len(study.conditions) == 5
    assert (out / "robustness_DiffDriveRobot-v0_effort.png").stat().st_size > 0
    rows = [line.split("|")[1].strip() for line in
            (out / "robustness.md").read_text().splitlines() if line.startswith("| ")]
    assert OPTIMAL in rows and FOLLOWER in rows and LQR in rows
    # one line per episode: the open loop, the floor and the LQR under 0.01 and the four
    # mismatches
    assert len((out / "episodes.jsonl").read_text().splitlines()) == 3 * 5
    # a run of another objective keeps this one's rows in robustness.md
    assert run("robustness", ROBOT, "--objective", "time", "--seeds", "1", "--scales", "0.01",
               "--no-mismatch", "--trained", str(tmp_path), "--output", str(out)) == 0
    table = (out / "robustness.md").read_text()
    assert "DiffDriveRobot-v0 effort" in table and "DiffDriveRobot-v0 time" in table


def test_the_shipped_tables_are_made_from_the_shipped_studies() -> None:
    folder = RESULTS / "comparison"
    comparisons = [read_study(p) for p in sorted(folder.glob("compare_*.json"))]
    assert len(comparisons) == 6  # the v0 and the v1 id of each task
    assert (folder / "compare.md").read_text() == comparison_report(comparisons)
    for study in comparisons:
        assert (folder / f"compare_{study.name}.md").read_text() == comparison_report([study])
    studies = [read_study(p) for p in sorted((RESULTS / "robustness").glob("robustness_*.json"))]
    assert (RESULTS / "robustness" / "robustness.md").read_text().strip() == robustness_table(
        studies)
    for study in studies:  # every row has an aggregate under every condition
        assert all(row.aggregate(c.label) for row in study.rows for c in study.conditions)


def test_interval_text_says_n_and_never_shows_one_run_as_an_interval() -> None:
    from baselines.records import Estimate

    assert interval_text(Estimate(1, 0, 0.95, 0.95, None, [0.95]), percent=True) == (
        "95 % (n=1, no CI)")
    assert interval_text(Estimate(4, 1, 1.3, 1.234, (1.1, 1.5), [])) == (
        "1.23 [1.10, 1.50] (n=4, 1 without)")
    assert interval_text(Estimate(0, 2, None, None, None, [])) == "-"


@pytest.mark.slow
def test_compare_aggregates_the_seeds_of_an_algorithm(tmp_path: Path) -> None:
    """Two tiny PPO runs (seeds 1, 2) form one row: n=2, a CI, curves from their CSVs."""
    import torch

    from baselines.aggregate import CURVE_POINTS
    from baselines.plots import read_curve
    from baselines.train import train

    torch.set_num_threads(1)
    overrides = {"n_steps": 64, "batch_size": 64, "n_epochs": 1,
                 "policy_kwargs": {"net_arch": [8, 8]}}  # fmt: skip
    for seed in (1, 2):  # 2 copies x 576 steps: each copy ends one 500-step episode
        train(MANIPULATOR, "PPO", seed=seed, total_timesteps=1100, output=tmp_path, num_envs=2,
              algo_overrides=overrides, eval_episodes=0, progress_bar=False)  # fmt: skip
    assert run("compare", MANIPULATOR, "--seeds", "2", "--bootstrap-reps", "200", "--trained",
               str(tmp_path), "--output", str(tmp_path / "out")) == 0
    study = read_study(tmp_path / "out" / "compare_BlockableManipulator-v0_time.json")
    ppo = study.row("PPO")
    assert ppo.trained and [run.seed for run in ppo.runs] == [1, 2]
    success = ppo.aggregate("perturbation 0.01").success_rate
    assert success.n == 2 and success.ci is not None
    assert success.ci[0] <= success.iqm <= success.ci[1]
    table = (tmp_path / "out" / "compare.md").read_text()
    assert "2 seeds x 2 starts" in table and "1.2e+03 steps, 2 envs, seeds 1-2" in table
    steps, rates = read_curve(ppo.runs[0].training, tmp_path)
    assert len(steps) == len(rates) == CURVE_POINTS and np.all(np.diff(steps) >= 0)
