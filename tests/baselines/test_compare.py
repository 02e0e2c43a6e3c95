"""The RL-vs-optimal evaluation, checked with the optimal controls and a random policy."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from baselines.compare import (
    OPTIMAL,
    Episode,
    compare,
    markdown_table,
    reference_controller,
    reference_effort,
    shipped_policies,
    summarize,
    write_comparison,
)
from optimal.references import load_reference

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"


def random_controller(env_id: str, **env_kwargs: object) -> tuple:
    """A seeded random policy factory and its env arguments."""

    def factory():  # type: ignore[no-untyped-def]
        space = gym.make(env_id, **env_kwargs).action_space
        space.seed(0)
        return lambda _obs: space.sample()

    return factory, dict(env_kwargs)


@pytest.fixture(scope="module")
def manipulator_comparison() -> dict:
    """The optimum, its own controls as an extra "policy", and a random policy; 2 seeds."""
    reference = load_reference("manipulator_time")
    return compare(MANIPULATOR, "time", num_seeds=2, policies=[], extra_controllers={
        "reference controls": reference_controller(reference),
        "random": random_controller(MANIPULATOR),
    })  # fmt: skip


def _row(comparison: dict, label: str) -> dict:
    return next(row for row in comparison["controllers"] if row["label"] == label)


def test_optimal_controls_score_ratio_one(manipulator_comparison: dict) -> None:
    for label in (OPTIMAL, "reference controls"):
        nominal = _row(manipulator_comparison, label)["nominal"]
        assert nominal.is_success
        assert nominal.elapsed_time / manipulator_comparison["optimal_time"] == pytest.approx(
            1.0, abs=1e-9)
        assert nominal.effort / manipulator_comparison["optimal_effort"] == pytest.approx(
            1.0, rel=1e-6)  # float32 actions: torques rounded to ~6e-8 relative
        assert nominal.schedule.shape == (nominal.num_steps,)
        assert nominal.q.shape == (nominal.num_steps + 1, 2)
        assert nominal.solver_failures == 0


def test_random_policy_is_reported_as_failure(manipulator_comparison: dict) -> None:
    row = _row(manipulator_comparison, "random")
    assert row["summary"]["success_rate"] == 0.0
    assert row["summary"]["time_ratio"] is None and row["summary"]["effort_ratio"] is None
    assert not row["nominal"].is_success
    assert all(e.elapsed_time == pytest.approx(10.0) for e in row["episodes"])  # truncated
    table = markdown_table([manipulator_comparison])
    assert "| random | 0% of 2 | - | - | fails |" in table


def test_perturbed_starts_differ_from_nominal(manipulator_comparison: dict) -> None:
    row = _row(manipulator_comparison, OPTIMAL)
    starts = [e.q[0] for e in row["episodes"]]
    assert not np.allclose(starts[0], starts[1])
    assert 0.0 < np.max(np.abs(starts[0] - row["nominal"].q[0])) <= 0.01


def test_effort_task_reference_ratio_one() -> None:
    reference = load_reference("diff_drive_effort")
    assert reference_effort(reference) == pytest.approx(reference.cost, rel=1e-12)
    comparison = compare(DIFF_DRIVE, "effort", num_seeds=1, policies=[])
    nominal = _row(comparison, OPTIMAL)["nominal"]
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
    json_path, png_path = write_comparison(manipulator_comparison, tmp_path)
    record = json.loads(json_path.read_text())
    assert [row["label"] for row in record["controllers"]] == [OPTIMAL, "reference controls",
                                                                 "random"]  # fmt: skip
    assert len(record["controllers"][0]["episodes"]) == 2
    assert png_path.stat().st_size > 10_000


def test_unknown_task_is_rejected() -> None:
    with pytest.raises(ValueError, match="no optimal reference"):
        compare(MANIPULATOR, "effort")


def test_shipped_policies_match_env_and_task(tmp_path: Path) -> None:
    config = {"env_id": DIFF_DRIVE, "task": "effort", "algo": "PPO"}
    (tmp_path / "a.json").write_text(json.dumps(config))
    (tmp_path / "a.zip").write_bytes(b"")
    (tmp_path / "b.json").write_text(json.dumps({**config, "task": "time"}))
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
    with pytest.raises(SystemExit, match="has no task"):
        main(["compare", MANIPULATOR, "--task", "effort", "--output", str(tmp_path)])
