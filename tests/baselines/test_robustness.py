"""The robustness study: conditions, the env-only model mismatch, table and plot."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("stable_baselines3")

import baselines.robustness as robustness_module  # noqa: E402
from baselines.robustness import (  # noqa: E402
    MISMATCHES,
    main,
    merge_studies,
    read_episodes,
    robustness,
)
from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters  # noqa: E402

ROBOT = "mdi_envs/DiffDriveRobot-v0"


def test_mismatches_change_only_the_named_parameters() -> None:
    nominal = DiffDriveParameters()
    changed = dict(MISMATCHES[ROBOT])["friction -20 %"]()
    assert changed.wheel_friction == pytest.approx(0.8 * nominal.wheel_friction)
    assert changed.stick_friction == pytest.approx(0.8 * nominal.stick_friction)
    assert changed.mass == nominal.mass
    heavier = dict(MISMATCHES[ROBOT])["mass +10 %"]()
    assert heavier.mass == pytest.approx(1.1 * nominal.mass)


def test_open_loop_reference_is_played_under_every_condition(tmp_path: Path) -> None:
    study = robustness(ROBOT, "time", num_seeds=1, scales=(0.0, 0.3), trained_dir=tmp_path)
    labels = [c["label"] for c in study["conditions"]]
    assert labels[:2] == ["perturbation 0", "perturbation 0.3"] and len(labels) == 6
    (row,) = study["controllers"]  # no trained policies in tmp_path: the reference only
    by_condition = {r["condition"]: r for r in row["results"]}
    # from the unperturbed start the open-loop optimum reaches the goal at its own t_f
    assert by_condition["perturbation 0"]["success_rate"] == 1.0
    assert by_condition["perturbation 0"]["time_ratio"] == pytest.approx(1.0, abs=1e-6)
    # 0.3 m / rad of start error is far outside what open loop can absorb
    assert by_condition["perturbation 0.3"]["success_rate"] == 0.0


def test_cli_writes_json_plot_and_table(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main([ROBOT, "--objective", "effort", "--seeds", "1", "--scales", "0.01",
                 "--trained", str(tmp_path), "--output", str(out)]) == 0
    study = json.loads((out / "robustness_DiffDriveRobot-v0_effort.json").read_text())
    assert study["objective"] == "effort" and study["seeds"] == 1
    assert (out / "robustness_DiffDriveRobot-v0_effort.png").stat().st_size > 0
    assert "| optimal (open loop) | 1 |" in (out / "robustness.md").read_text()
    # one line per episode: the open loop under 0.01 and the four mismatches
    assert len((out / "episodes.jsonl").read_text().splitlines()) == 5
    # a rerun of another env x objective keeps this one's rows in robustness.md
    assert main([ROBOT, "--objective", "time", "--seeds", "1", "--scales", "0.01", "--no-mismatch",
                 "--trained", str(tmp_path), "--output", str(out)]) == 0
    table = (out / "robustness.md").read_text()
    assert "DiffDriveRobot-v0 effort" in table and "DiffDriveRobot-v0 time" in table


def test_a_controller_rerun_merges_into_the_study(tmp_path: Path) -> None:
    out = tmp_path / "out"
    common = [ROBOT, "--objective", "effort", "--seeds", "1", "--no-mismatch", "--trained",
              str(tmp_path), "--output", str(out)]
    assert main([*common, "--scales", "0.01"]) == 0
    assert main([*common, "--scales", "0.3", "--controllers", "optimal (open loop)"]) == 0
    study = json.loads((out / "robustness_DiffDriveRobot-v0_effort.json").read_text())
    assert [c["label"] for c in study["conditions"]] == ["perturbation 0.01",
                                                         "perturbation 0.3"]
    (row,) = study["controllers"]
    assert [r["condition"] for r in row["results"]] == ["perturbation 0.01", "perturbation 0.3"]
    assert row["results"][1]["success_rate"] == 0.0  # the open loop at 0.3 (as above)
    # one mismatch alone, no perturbation scale: merged after the scales
    assert main([ROBOT, "--objective", "effort", "--seeds", "1", "--trained", str(tmp_path),
                 "--output", str(out), "--scales", "--mismatches", "friction +20 %",
                 "--controllers", "optimal (open loop)"]) == 0
    study = json.loads((out / "robustness_DiffDriveRobot-v0_effort.json").read_text())
    assert [c["label"] for c in study["conditions"]] == ["perturbation 0.01", "perturbation 0.3",
                                                         "friction +20 %"]
    # a trained algorithm whose policies are gone from --trained leaves the study at a merge
    withdrawn = {**study["controllers"][0], "label": "SAC"}
    path = out / "robustness_DiffDriveRobot-v0_effort.json"
    path.write_text(json.dumps({**study, "controllers": [*study["controllers"], withdrawn]}))
    assert main([*common, "--scales", "0.3", "--controllers", "optimal (open loop)"]) == 0
    labels = [row["label"] for row in json.loads(path.read_text())["controllers"]]
    assert labels == ["optimal (open loop)"]
    with pytest.raises(ValueError, match="seeds"):
        merge_studies(study, {**study, "seeds": 2})


def test_an_unknown_mismatch_label_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"unknown mismatch \['mass \+20 %'\]"):
        robustness(ROBOT, "effort", num_seeds=1, scales=(), trained_dir=tmp_path,
                   mismatches=["mass +20 %"])


def test_an_unknown_controller_label_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"no controller 'PP0'.*known: optimal \(open loop\)"):
        robustness(ROBOT, "effort", num_seeds=1, scales=(0.01,), trained_dir=tmp_path,
                   mismatches=False, only=["PP0"])


def test_an_interrupted_study_resumes_from_its_episodes(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "episodes.jsonl"
    options = {"num_seeds": 2, "scales": (0.01,), "mismatches": False, "trained_dir": tmp_path,
               "episodes_path": path}
    first = robustness(ROBOT, "effort", **options)
    lines = path.read_text().splitlines()
    assert [json.loads(line)["seed"] for line in lines] == [0, 1]
    # killed while writing seed 1: its line cut short
    path.write_text(lines[0] + "\n" + lines[1][:20])
    played: list[int] = []
    real_play = robustness_module.play

    def counting_play(*args: Any, **kwargs: Any) -> Any:
        played.append(args[2])
        return real_play(*args, **kwargs)

    monkeypatch.setattr(robustness_module, "play", counting_play)
    assert robustness(ROBOT, "effort", **options, resume=True) == first
    assert played == [1]  # seed 0 read back, seed 1 played again
    assert read_episodes(path, ROBOT, "effort").keys() == {
        ("optimal (open loop)", 0, "perturbation 0.01", seed) for seed in (0, 1)}
    assert read_episodes(path, ROBOT, "time") == {}
    played.clear()
    assert robustness(ROBOT, "effort", **options) == first  # without resume: every episode
    assert played == [0, 1]
