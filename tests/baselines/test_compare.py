"""The RL-vs-optimal evaluation, checked with the optimal controls and a random policy."""

from __future__ import annotations

import json
import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from baselines.aggregate import CURVE_POINTS
from baselines.compare import (
    CONTROLLER_FACTORIES,
    OPTIMAL,
    Controller,
    Episode,
    collect_tables,
    compare,
    group_by_algorithm,
    interval_text,
    markdown_table,
    merge_comparisons,
    reference_controller,
    reference_effort,
    registered_controllers,
    shipped_policies,
    summarize,
    write_comparison,
)
from optimal.references import load_reference

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"


def random_controller() -> Controller:
    """A seeded random policy on the env it is given."""

    def make_policy(env: gym.Env) -> object:
        space = env.action_space
        space.seed(0)
        return lambda _obs: space.sample()

    return Controller("random", make_policy)


@pytest.fixture(scope="module")
def manipulator_comparison() -> dict:
    """The optimum, its own controls as an extra controller, and a random policy; 2 starts."""
    reference = load_reference("manipulator_time")
    return compare(MANIPULATOR, "time", num_seeds=2, policies=[], extra_controllers=[
        reference_controller(reference, "reference controls"), random_controller()])


def _row(comparison: dict, label: str) -> dict:
    return next(row for row in comparison["controllers"] if row["label"] == label)


def _run(comparison: dict, label: str) -> dict:
    """The only run of an untrained controller."""
    (run,) = _row(comparison, label)["runs"]
    return run


def test_optimal_controls_score_the_optimum(manipulator_comparison: dict) -> None:
    reference = load_reference("manipulator_time")
    for label in (OPTIMAL, "reference controls"):
        nominal = _run(manipulator_comparison, label)["nominal"]
        assert nominal.is_success
        # the env ends the episode once within its success tolerances: at t_f, or (this
        # optimum) 2 steps before it; time and effort are the optimum's up to that step
        steps = nominal.num_steps
        assert reference.tau.shape[0] - 3 <= steps <= reference.tau.shape[0]
        assert nominal.elapsed_time == pytest.approx(reference.time[steps], abs=1e-9)
        assert nominal.elapsed_time <= manipulator_comparison["optimal_time"] + 1e-9
        effort = float(np.sum(reference.tau[:steps] ** 2) * reference.time_step)
        assert nominal.effort == pytest.approx(effort, rel=1e-6)  # float32 actions
        assert nominal.schedule.shape == (nominal.num_steps,)
        assert nominal.q.shape == (nominal.num_steps + 1, 2)
        assert nominal.solver_failures == 0


def test_random_policy_is_reported_as_failure(manipulator_comparison: dict) -> None:
    run = _run(manipulator_comparison, "random")
    assert run["summary"]["success_rate"] == 0.0
    assert run["summary"]["time_ratio"] is None and run["summary"]["effort_ratio"] is None
    assert not run["nominal"].is_success
    assert all(e.elapsed_time == pytest.approx(10.0) for e in run["episodes"])  # truncated
    aggregate = _row(manipulator_comparison, "random")["aggregate"]
    assert aggregate["time_ratio"] == {"n": 0, "missing": 1, "iqm": None, "ci": None,
                                       "values": []}  # fmt: skip
    table = markdown_table([manipulator_comparison])
    assert "| random | controller, 2 starts | 0 % | - | - | fails | " in table
    assert run["summary"]["compute_per_step"] > 0.0  # each policy call timed
    assert re.search(r"\| fails \| [0-9.e-]+ ms \|  \|", table)


def test_perturbed_starts_differ_from_nominal(manipulator_comparison: dict) -> None:
    run = _run(manipulator_comparison, OPTIMAL)
    starts = [e.q[0] for e in run["episodes"]]
    assert not np.allclose(starts[0], starts[1])
    assert 0.0 < np.max(np.abs(starts[0] - run["nominal"].q[0])) <= 0.01


def test_effort_task_reference_ratio_one() -> None:
    reference = load_reference("diff_drive_effort")
    assert reference_effort(reference) == pytest.approx(reference.cost, rel=1e-12)
    comparison = compare(DIFF_DRIVE, "effort", num_seeds=1, policies=[])
    nominal = _run(comparison, OPTIMAL)["nominal"]
    assert nominal.is_success
    assert nominal.effort / comparison["optimal_effort"] == pytest.approx(1.0, rel=1e-6)
    assert set(np.unique(nominal.schedule)) <= {2.0, 3.0, 5.0}


def test_summarize_counts_only_successes() -> None:
    def episode(success: bool, time: float, effort: float) -> Episode:
        return Episode(0, True, success, time, effort, 0.0, 1, 0, np.zeros(2),
                       np.zeros((2, 2)), np.zeros(1))  # fmt: skip

    summary = summarize([episode(True, 6.0, 4.0), episode(True, 9.0, 2.0),
                         episode(False, 10.0, 50.0)], optimal_time=3.0, optimal_effort=2.0)
    assert summary["success_rate"] == pytest.approx(2 / 3)
    assert summary["time_ratio"] == pytest.approx(2.5)
    assert summary["time_ratio_median"] == pytest.approx(2.5)
    assert summary["effort_ratio"] == pytest.approx(1.5)


def test_write_comparison(manipulator_comparison: dict, tmp_path: Path) -> None:
    json_path, png_path, seeds_path, table_path = write_comparison(manipulator_comparison,
                                                                   tmp_path)
    assert collect_tables(tmp_path) == table_path.read_text().strip()
    record = json.loads(json_path.read_text())
    assert [row["label"] for row in record["controllers"]] == [OPTIMAL, "reference controls",
                                                                 "random"]  # fmt: skip
    assert len(record["controllers"][0]["runs"][0]["episodes"]) == 2
    optimal = record["controllers"][0]
    assert optimal["aggregate"]["success_rate"]["iqm"] == optimal["runs"][0]["summary"][
        "success_rate"]  # one run: its own score, no interval
    assert optimal["aggregate"]["success_rate"]["ci"] is None
    assert png_path.stat().st_size > 10_000 and seeds_path.stat().st_size > 10_000


def test_controller_hook_names_the_optimal_reference() -> None:
    assert CONTROLLER_FACTORIES[0] == "baselines.compare:optimal_controller"
    assert [c.label for c in registered_controllers(DIFF_DRIVE, "effort")] == [OPTIMAL]
    assert registered_controllers(MANIPULATOR, "effort") == []  # no reference: no row


def test_interval_text_says_n_and_never_shows_one_run_as_an_interval() -> None:
    one = {"n": 1, "missing": 0, "iqm": 0.95, "ci": None, "values": [0.95]}
    assert interval_text(one, percent=True) == "95 % (n=1, no CI)"
    five = {"n": 4, "missing": 1, "iqm": 1.234, "ci": [1.1, 1.5], "values": []}
    assert interval_text(five) == "1.23 [1.10, 1.50] (n=4, 1 without)"
    assert interval_text({"n": 0, "missing": 2, "iqm": None, "ci": None, "values": []}) == "-"


def test_group_by_algorithm_sorts_seeds(tmp_path: Path) -> None:
    for seed in (2, 0, 1):
        (tmp_path / f"p{seed}.json").write_text(json.dumps({"algo": "PPO", "seed": seed}))
    (tmp_path / "s.json").write_text(json.dumps({"algo": "SAC", "seed": 0}))
    groups = group_by_algorithm(sorted(tmp_path.glob("*.json")))
    assert groups == {"PPO": [tmp_path / f"p{s}.json" for s in (0, 1, 2)],
                      "SAC": [tmp_path / "s.json"]}  # fmt: skip


def test_unknown_task_is_rejected() -> None:
    with pytest.raises(ValueError, match="no optimal reference"):
        compare(MANIPULATOR, "effort")


def test_shipped_policies_match_env_and_task(tmp_path: Path) -> None:
    config = {"env_id": DIFF_DRIVE, "objective": "effort", "algo": "PPO"}
    (tmp_path / "a.json").write_text(json.dumps(config))
    (tmp_path / "a.zip").write_bytes(b"")
    (tmp_path / "b.json").write_text(json.dumps({**config, "objective": "time"}))
    (tmp_path / "b.zip").write_bytes(b"")
    (tmp_path / "c.json").write_text(json.dumps(config))  # no zip beside it
    assert shipped_policies(DIFF_DRIVE, "effort", tmp_path) == [tmp_path / "a.json"]


def test_compare_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from mdi_envs.cli import main

    assert main(["compare", MANIPULATOR, "--seeds", "1", "--output", str(tmp_path)]) == 0
    table = capsys.readouterr().out
    assert f"| BlockableManipulator-v0 | time | {OPTIMAL} | " in table
    assert (tmp_path / "compare.md").read_text().strip() == table.strip()
    assert (tmp_path / "compare_BlockableManipulator-v0_time.png").exists()
    with pytest.raises(SystemExit, match="has no objective"):
        main(["compare", MANIPULATOR, "--objective", "effort", "--output", str(tmp_path)])


def test_a_row_rerun_merges_into_the_comparison(tmp_path: Path) -> None:
    from mdi_envs.cli import main

    common = ["compare", DIFF_DRIVE, "--objective", "effort", "--seeds", "1", "--trained",
              str(tmp_path), "--output", str(tmp_path)]  # fmt: skip
    assert main(common) == 0
    path = tmp_path / "compare_DiffDriveRobot-v0_effort.json"
    first = json.loads(path.read_text())
    nominal = first["controllers"][0]["runs"][0]["nominal"]
    assert len(nominal["trajectory"]["q"]) == nominal["num_steps"] + 1  # kept for merges
    row = first["controllers"][0]
    withdrawn = {**row, "label": "SAC", "algo": "SAC", "trained": True}  # no SAC in --trained
    kept = {**first, "controllers": [{**row, "label": "kept row"}, withdrawn]}
    path.write_text(json.dumps(kept))
    assert main([*common, "--controllers", OPTIMAL]) == 0
    merged = json.loads(path.read_text())
    # the untrained row stays; the trained row whose policies are gone is dropped
    assert [row["label"] for row in merged["controllers"]] == ["kept row", OPTIMAL]
    assert merged["controllers"][0]["runs"] == first["controllers"][0]["runs"]
    assert "| kept row |" in (tmp_path / "compare.md").read_text()
    with pytest.raises(SystemExit, match="no controller 'PP0'"):
        main([*common, "--controllers", "PP0"])
    with pytest.raises(ValueError, match="different seeds"):
        merge_comparisons(merged, {**merged, "seeds": [0, 1]})


@pytest.mark.slow
def test_compare_aggregates_the_seeds_of_an_algorithm(tmp_path: Path) -> None:
    """Two tiny PPO runs (seeds 1, 2) form one row: IQM, a CI, n=2, curves from their CSVs."""
    import torch

    from baselines.seed_plots import run_curve
    from baselines.train import train

    torch.set_num_threads(1)
    overrides = {"n_steps": 64, "batch_size": 64, "n_epochs": 1,
                 "policy_kwargs": {"net_arch": [8, 8]}}  # fmt: skip
    for seed in (1, 2):  # 2 copies x 576 steps: each copy ends one 500-step episode
        train(MANIPULATOR, "PPO", seed=seed, total_timesteps=1100, output=tmp_path, num_envs=2,
              algo_overrides=overrides, eval_episodes=0, progress_bar=False)  # fmt: skip
    comparison = compare(MANIPULATOR, "time", num_seeds=2, trained_dir=tmp_path,
                         bootstrap_reps=200)  # fmt: skip
    row = _row(comparison, "PPO")
    assert row["trained"] and [run["seed"] for run in row["runs"]] == [1, 2]
    success = row["aggregate"]["success_rate"]
    assert success["n"] == 2 and success["ci"] is not None
    assert success["ci"][0] <= success["iqm"] <= success["ci"][1]
    table = markdown_table([comparison])
    assert "| PPO | 2 seeds x 2 starts | " in table and "(n=2)" in table
    assert "1.2e+03 steps, 2 envs, seeds 1-2 |" in table  # 1152 steps taken
    steps, rates = run_curve(row["runs"][0]["config"], tmp_path)
    assert len(steps) == len(rates) == CURVE_POINTS and np.all(np.diff(steps) >= 0)
    paths = write_comparison(comparison, tmp_path / "out", tmp_path)
    assert all(path.stat().st_size > 10_000 for path in paths[1:3])  # the plots
