"""The evaluation framework, checked with the optimal controls, a random policy and the records."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import baselines.evaluation as evaluation_module
from baselines.evaluation import (
    CONTROLLER_FACTORIES,
    DIFF_DRIVE_EFFORT_V1,
    MISMATCHES,
    Controller,
    evaluate,
    group_by_algorithm,
    merge,
    read_log,
    reference_controller,
    reference_effort,
    register_controller,
    registered_controllers,
    shipped_policies,
)
from baselines.heuristics import BANG_BANG, FOLLOWER
from baselines.model_based import LQR
from baselines.records import (
    OPTIMAL,
    BrakeUse,
    Condition,
    Episode,
    Scores,
    Study,
    read_study,
    write_study,
)
from baselines.tables import brake_use_table, engaged_intervals, improvement_table
from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters
from optimal.references import load_reference

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
ROBOT = "mdi_envs/DiffDriveRobot-v0"


def random_controller() -> Controller:
    """A seeded random policy on the env it is given."""

    def make_policy(env: gym.Env) -> object:
        space = env.action_space
        space.seed(0)
        return lambda _obs: space.sample()

    return Controller("random", make_policy)


@pytest.fixture(scope="module")
def manipulator_study(tmp_path_factory: pytest.TempPathFactory) -> Study:
    """The optimum, its own controls as an extra controller, and a random policy; 2 starts."""
    reference = load_reference("manipulator_time")
    return evaluate(MANIPULATOR, "time", num_starts=2, nominal=True,
                    trained_dir=tmp_path_factory.mktemp("none"), extra_controllers=[
                        reference_controller(reference, "reference controls"),
                        random_controller()])  # fmt: skip


def test_optimal_controls_score_the_optimum(manipulator_study: Study) -> None:
    reference = load_reference("manipulator_time")
    for label in (OPTIMAL, "reference controls"):
        (run,) = manipulator_study.row(label).runs
        nominal = run.nominal
        assert nominal is not None and nominal.is_success and nominal.trajectory is not None
        # the env ends the episode once within its success tolerances: at t_f, or (this
        # optimum) 2 steps before it; time and effort are the optimum's up to that step
        steps = nominal.num_steps
        assert reference.tau.shape[0] - 3 <= steps <= reference.tau.shape[0]
        assert nominal.elapsed_time == pytest.approx(reference.time[steps], abs=1e-9)
        assert nominal.elapsed_time <= manipulator_study.optimal_time + 1e-9
        effort = float(np.sum(reference.tau[:steps] ** 2) * reference.time_step)
        assert nominal.effort == pytest.approx(effort, rel=1e-6)  # float32 actions
        assert len(nominal.trajectory.schedule) == steps
        assert np.shape(nominal.trajectory.q) == (steps + 1, 2)
        assert nominal.solver_failures == 0
        assert run.training is None and run.seed is None and run.commit


def test_brake_use_of_the_optimum_is_its_schedule(manipulator_study: Study) -> None:
    """The env's brake record of the replayed optimum against the NLP's brake and impulses."""
    reference = load_reference("manipulator_time")
    nominal = manipulator_study.row(OPTIMAL).runs[0].nominal
    steps, h = nominal.num_steps, reference.time_step
    engaged = reference.brake_bound[:steps, 0] > 0.0
    starts = np.flatnonzero(engaged & ~np.concatenate(([False], engaged[:-1])))
    use = nominal.brake_use
    assert use is not None and use.engagements == len(starts) >= 2
    assert use.first_engagement == pytest.approx(starts[0] * h, rel=1e-9)
    assert use.engaged_time == pytest.approx(engaged.sum() * h, rel=1e-9)
    impulses = reference.arrays["brake_impulse"][:steps]
    assert use.impulse == pytest.approx(np.abs(impulses).sum(), rel=1e-4)
    intervals = engaged_intervals(nominal)
    assert [a for a, _ in intervals] == pytest.approx(list(starts * h), rel=1e-9)
    assert sum(b - a for a, b in intervals) == pytest.approx(use.engaged_time, rel=1e-9)


def test_brake_use_counts_engagements() -> None:
    use = BrakeUse.of([1, 1, 0, 0, 1, 0, 1], [0.5, 0.0, 0.0, 0.0, -0.25, 0.0, 0.125], 0.1)
    assert use == BrakeUse(engagements=3, engaged_time=pytest.approx(0.4), first_engagement=0.0,
                           impulse=0.875)  # fmt: skip
    never = BrakeUse.of([0, 0], [0.0, 0.0], 0.1)
    assert never.engagements == 0 and never.first_engagement is None and never.impulse == 0.0


def test_brake_use_table_lists_the_brake_rows(manipulator_study: Study, tmp_path: Path) -> None:
    table = brake_use_table([manipulator_study])
    assert all(label in table for label in (OPTIMAL, "reference controls", "random"))
    robot = evaluate(ROBOT, "time", num_starts=1, trained_dir=tmp_path)
    assert robot.row(OPTIMAL).runs[0].episodes[0].brake_use is None
    assert brake_use_table([robot]) == ""


def test_improvement_table_pairs_trained_rows_with_the_others(manipulator_study: Study) -> None:
    rows = [dataclasses.replace(row, trained=row.label == "random")
            for row in manipulator_study.rows]  # fmt: skip
    lines = improvement_table([dataclasses.replace(manipulator_study, rows=rows)],
                              reps=0).splitlines()[2:]  # fmt: skip
    pairs = [[cell.strip() for cell in line.split("|")[4:8]] for line in lines]
    others = [row.label for row in rows if row.label not in (OPTIMAL, "random")]
    assert BANG_BANG in others and "reference controls" in others
    assert [pair[:2] for pair in pairs] == [["random", label] for label in others]
    for pair in pairs:  # no CI with one run each; it never reaches the goal
        assert float(pair[2]) <= 0.5 and float(pair[3]) <= 0.5


def test_random_policy_is_reported_as_failure(manipulator_study: Study) -> None:
    (run,) = manipulator_study.row("random").runs
    assert run.scores.success_rate == 0.0
    assert run.scores.time_ratio is None and run.scores.effort_ratio is None
    assert run.nominal is not None and not run.nominal.is_success
    assert all(e.elapsed_time == pytest.approx(10.0) for e in run.episodes)  # truncated
    assert run.scores.compute_per_step > 0.0  # each policy call timed


def test_perturbed_starts_differ_from_nominal(manipulator_study: Study) -> None:
    (run,) = manipulator_study.row(OPTIMAL).runs
    starts = [np.asarray(e.trajectory.q[0]) for e in run.episodes]  # first run: trajectories
    assert not np.allclose(starts[0], starts[1])
    assert 0.0 < np.max(np.abs(starts[0] - np.asarray(run.nominal.trajectory.q[0]))) <= 0.01


def test_the_perturbation_scale_is_a_parameter(tmp_path: Path) -> None:
    study = evaluate(ROBOT, "time", [Condition(0.0), Condition(0.3)], num_starts=1,
                     trained_dir=tmp_path)  # fmt: skip
    assert [c.label for c in study.conditions] == ["perturbation 0", "perturbation 0.3"]
    assert [row.label for row in study.rows] == [OPTIMAL, FOLLOWER, LQR]  # no trained policies
    exact, far = (run.scores for run in study.row(OPTIMAL).runs)
    # from the unperturbed start the open-loop optimum reaches the goal at its own t_f
    assert exact.success_rate == 1.0 and exact.time_ratio == pytest.approx(1.0, abs=1e-6)
    assert far.success_rate == 0.0  # 0.3 m / rad of start error: open loop cannot absorb it


@pytest.mark.parametrize("env_id", [ROBOT, DIFF_DRIVE_EFFORT_V1])
def test_effort_task_reference_ratio_one(tmp_path: Path, env_id: str) -> None:
    reference = load_reference("diff_drive_effort")
    assert reference_effort(reference) == pytest.approx(reference.cost, rel=1e-12)
    study = evaluate(env_id, "effort", num_starts=1, nominal=True, trained_dir=tmp_path)
    nominal = study.row(OPTIMAL).runs[0].nominal
    assert nominal is not None and nominal.is_success
    assert nominal.effort / study.optimal_effort == pytest.approx(1.0, rel=1e-6)
    assert set(nominal.trajectory.schedule) <= {2.0, 3.0, 5.0}


def test_scores_count_only_successes() -> None:
    def episode(success: bool, time: float, effort: float) -> Episode:
        return Episode(0, success, time, effort, 0, 1e-3)

    scores = Scores.of([episode(True, 6.0, 4.0), episode(True, 9.0, 2.0),
                        episode(False, 10.0, 50.0)], optimal_time=3.0, optimal_effort=2.0)
    assert scores.success_rate == pytest.approx(2 / 3)
    assert scores.time_ratio == pytest.approx(2.5) and scores.time_ratio_median == 2.5
    assert scores.effort_ratio == pytest.approx(1.5)
    assert scores.compute_per_step == pytest.approx(1e-3)


def test_the_controller_registry(monkeypatch: pytest.MonkeyPatch) -> None:
    assert CONTROLLER_FACTORIES[0] == "baselines.evaluation:optimal_controller"
    assert [c.label for c in registered_controllers(ROBOT, "effort")] == [OPTIMAL, FOLLOWER, LQR]
    assert [c.label for c in registered_controllers(MANIPULATOR, "time")] == [OPTIMAL, BANG_BANG,
                                                                             LQR]
    assert registered_controllers(MANIPULATOR, "effort") == []  # no reference: no row
    monkeypatch.setattr(evaluation_module, "CONTROLLER_FACTORIES", list(CONTROLLER_FACTORIES))
    register_controller(f"{__name__}:random_factory")
    register_controller(f"{__name__}:random_factory")  # idempotent
    assert [c.label for c in registered_controllers(ROBOT, "time")] == [OPTIMAL, FOLLOWER, LQR,
                                                                       "random"]  # fmt: skip
    with pytest.raises(ValueError, match="module:function"):
        register_controller("random_factory")


def random_factory(env_id: str, objective: str) -> Controller:
    """A ``ControllerFactory`` for the registry test."""
    return random_controller()


def test_group_by_algorithm_sorts_seeds(tmp_path: Path) -> None:
    for seed in (2, 0, 1):
        (tmp_path / f"p{seed}.json").write_text(json.dumps({"algo": "PPO", "seed": seed}))
    (tmp_path / "s.json").write_text(json.dumps({"algo": "SAC", "seed": 0}))
    groups = group_by_algorithm(sorted(tmp_path.glob("*.json")))
    assert groups == {"PPO": [tmp_path / f"p{s}.json" for s in (0, 1, 2)],
                      "SAC": [tmp_path / "s.json"]}  # fmt: skip


def test_shipped_policies_match_env_and_task(tmp_path: Path) -> None:
    config = {"env_id": ROBOT, "objective": "effort", "algo": "PPO"}
    (tmp_path / "a.json").write_text(json.dumps(config))
    (tmp_path / "a.zip").write_bytes(b"")
    (tmp_path / "b.json").write_text(json.dumps({**config, "objective": "time"}))
    (tmp_path / "b.zip").write_bytes(b"")
    (tmp_path / "c.json").write_text(json.dumps(config))  # no zip beside it
    assert shipped_policies(ROBOT, "effort", tmp_path) == [tmp_path / "a.json"]


def test_bad_requests_are_errors(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no optimal reference"):
        evaluate(MANIPULATOR, "effort")
    with pytest.raises(ValueError, match=r"unknown mismatch \['mass \+20 %'\]"):
        evaluate(ROBOT, "effort", [Condition(0.01, "mass +20 %")], 1, trained_dir=tmp_path)
    with pytest.raises(ValueError, match=r"no controller 'PP0'.*known: optimal \(open loop\)"):
        evaluate(ROBOT, "effort", num_starts=1, trained_dir=tmp_path, only=["PP0"])


def test_mismatches_change_only_the_named_parameters() -> None:
    nominal = DiffDriveParameters()
    changed = MISMATCHES[ROBOT]["friction -20 %"]()
    assert changed.wheel_friction == pytest.approx(0.8 * nominal.wheel_friction)
    assert changed.stick_friction == pytest.approx(0.8 * nominal.stick_friction)
    assert changed.mass == nominal.mass
    assert MISMATCHES[ROBOT]["mass +10 %"]().mass == pytest.approx(1.1 * nominal.mass)


def test_a_study_reads_back_from_json(manipulator_study: Study, tmp_path: Path) -> None:
    from pydantic import ValidationError

    path = write_study(manipulator_study, tmp_path / "study.json")
    assert read_study(path) == manipulator_study
    data = json.loads(path.read_text())
    data["rows"][0]["runs"][0]["scores"]["success_rate"] = "often"
    path.write_text(json.dumps(data))
    with pytest.raises(ValidationError, match="success_rate"):
        read_study(path)


def test_merge_orders_conditions_and_drops_withdrawn_rows(manipulator_study: Study) -> None:
    withdrawn = dataclasses.replace(manipulator_study.rows[0], label="PPO", trained=True)
    old = dataclasses.replace(manipulator_study, rows=[*manipulator_study.rows, withdrawn])
    mismatch = Condition(0.01, "link masses -10 %")
    moved = [dataclasses.replace(run, condition=mismatch) for run in old.rows[0].runs]
    new = dataclasses.replace(old, conditions=[mismatch, Condition(0.1)],
                              rows=[dataclasses.replace(old.rows[0], runs=moved)])
    merged = merge(old, new, shipped=set())
    assert [c.label for c in merged.conditions] == ["perturbation 0.01", "perturbation 0.1",
                                                    "link masses -10 %"]  # fmt: skip
    assert [row.label for row in merged.rows] == [OPTIMAL, BANG_BANG, LQR, "reference controls",
                                                  "random"]  # fmt: skip
    assert [run.condition for run in merged.rows[0].runs] == [Condition(), mismatch]
    assert merged.rows[1] == old.rows[1]  # a row not played again is kept as it was
    assert len(merge(old, new).rows) == 6  # no list of shipped algorithms: PPO kept
    with pytest.raises(ValueError, match="num_starts"):
        merge(old, dataclasses.replace(old, num_starts=3))


def test_an_interrupted_study_resumes_from_its_log(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "episodes.jsonl"
    options: dict[str, Any] = {"num_starts": 2, "trained_dir": tmp_path, "log_path": path,
                               "only": [OPTIMAL]}  # fmt: skip
    first = evaluate(ROBOT, "effort", **options)
    lines = path.read_text().splitlines()
    assert [json.loads(line)["episode"]["seed"] for line in lines] == [0, 1]
    path.write_text(lines[0] + "\n" + lines[1][:20])  # killed while writing seed 1
    played: list[int] = []
    real_play = evaluation_module.play

    def counting_play(*args: Any, **kwargs: Any) -> Any:
        played.append(args[2])
        return real_play(*args, **kwargs)

    monkeypatch.setattr(evaluation_module, "play", counting_play)
    again = evaluate(ROBOT, "effort", **options, resume=True)
    assert outcomes(again) == outcomes(first) and played == [1]  # seed 0 read back
    assert again.rows[0].runs[0].episodes[0] == first.rows[0].runs[0].episodes[0]
    assert set(read_log(path, ROBOT, "effort")) == {
        (OPTIMAL, 0, "perturbation 0.01", False, seed) for seed in (0, 1)}
    assert read_log(path, ROBOT, "time") == {}
    played.clear()
    assert outcomes(evaluate(ROBOT, "effort", **options)) == outcomes(first)  # every episode
    assert played == [0, 1]


def outcomes(study: Study) -> list[tuple[int, bool, float, float]]:
    """Every episode's seed, success, time and effort (its compute time is wall time)."""
    return [(e.seed, e.is_success, e.elapsed_time, e.effort)
            for row in study.rows for run in row.runs for e in run.episodes]  # fmt: skip
