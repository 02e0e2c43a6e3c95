"""The benchmark studies end to end on tiny configurations, and the headline table.

Times are not checked (the machine is shared); what does not depend on them is: the records'
keys, the rows each grid asks for, exact shortcuts reaching identical states, the solver entries
solving small well-posed problems to tolerance, the brake stopping the arm in one step, every
FC3D method converging on the small Siconos problems, and the headline collecting every target.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from peer_data import peer_files

from benchmarks import control, engine, fc3d, report, solvers, stress
from benchmarks.timing import TimingPlan

ONCE = TimingPlan(budget_s=0.0, min_rounds=1, max_rounds=1, min_batch_s=1e-5)


def load(path: Path) -> dict:
    assert path.stat().st_size > 0, path
    return json.loads(path.read_text())


def test_solvers_study_on_small_random_problems(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MDI_ENVS_PEER_DATA", str(tmp_path / "absent"))  # random problems only
    config = solvers.BenchConfig(sizes=(2, 12), instances=1, size_plan=ONCE, peer_sizes=(10,),
                                 peer_instances=1, peer_plan=ONCE, cold_compile=False)
    text = solvers.run(config, tmp_path, quick=True)
    record = load(tmp_path / "solvers.json")
    assert {"machine", "config", "first_call", "fixed_cost", "size_study", "quantecon_comparison",
            "run_time_s"} <= set(record)
    assert set(record["first_call"]["warm_cache"]["first_call_s"]) == {
        "lemke_solve", *solvers.E.LCP_METHODS, "quantecon"}
    aggregates = record["size_study"]["aggregates"]
    expected = {(family, n, entry) for family in ("spd", "contact") for n in (2, 12)
                for entry in (*solvers.E.LCP_METHODS, "quantecon")
                if entry != "enumerative" or n <= solvers.E.ENUMERATIVE_MAX_N}
    assert {(r["family"], r["n"], r["entry"]) for r in aggregates} == expected
    for row in aggregates:  # both families are well posed (M positive definite)
        assert row["solved"] == row["instances"] == 1 and row["residual_max"] < 1e-9, row
    problems = record["quantecon_comparison"]["problems"]
    assert [p["name"] for p in problems] == ["spd-n10-i0", "contact-n10-i0"]
    for problem in problems + record["fixed_cost"]:
        assert all(problem[key]["outcome"]["success"] for key in solvers.ENTRY_KEYS), problem
    assert [r["set"] for r in record["quantecon_comparison"]["median_ratios"]] == [
        "random (spd + contact)", "random spd (target: driver / QE <= 1)", "random contact"]
    for name in ("solvers_time_vs_size.png", "solvers_residual_vs_size.png",
                 "lemke_vs_quantecon.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert text.startswith("Run ") and "quantecon" in text.splitlines()[0]


def test_fc3d_study_on_the_small_peer_problems(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fc3d, "QUICK_MAX_N", 9)
    text = fc3d.run(tmp_path, quick=True)
    record = load(tmp_path / "fc3d.json")
    names = sorted(path.stem for path in peer_files("fc3d"))
    if not names:
        assert record["problems"] == [] and record["solved_by_any"] == 0
        return
    rows = record["problems"]
    assert rows and all(row["n"] <= 9 and row["name"] in names for row in rows)
    for row in rows:
        for method in fc3d.METHODS:
            assert row[method]["converged"] and row[method]["residual"] <= fc3d.TOL, (row, method)
    assert record["solved_by_any"] == len(rows)
    assert record["solved_by_method"] == dict.fromkeys(fc3d.METHODS, len(rows))
    assert (tmp_path / "fc3d.png").stat().st_size > 0 and text.startswith("Run ")


@pytest.mark.slow
def test_engine_study_on_a_tiny_grid(tmp_path: Path) -> None:
    # one shortcut off (a kernel compiled for it) on two scenes, and the free-against-solving
    # pairs; each shortcut's exactness is tests/stepping/test_shortcuts.py's
    cases = tuple(c for c in engine.SHORTCUT_CASES if c.model in ("ball", "manipulator")
                  and c.shortcut in ("reuse_constant_mass", "no_solve"))
    assert len(cases) == 4
    config = dataclasses.replace(
        engine.QUICK, models=("ball", "manipulator"), copies=(1, 4), call_s=1e-4,
        single_plan=ONCE, batch_plan=ONCE, shortcut_plan=ONCE, substep_plan=ONCE,
        scene_copies=4, shortcut_cases=cases, substep_grid=(1, 3), scene_min_substeps=2)
    text = engine.run(config, tmp_path, quick=True)
    record = load(tmp_path / "engine.json")
    assert {"machine", "config", "models", "compile", "single_step", "per_scene", "batched",
            "substeps", "shortcuts", "brake_stop", "targets", "load_log",
            "run_time_s"} <= set(record)
    scenes = {m["label"]: [s["name"] for s in m["scenes"]] for m in record["models"]}
    assert scenes == {"ball": ["resting", "bouncing", "in flight"],
                      "manipulator": ["engaged", "released", "tresca"]}
    assert record["models"][1]["scenes"][0]["brake"] == ["inf"]
    ours = {(r["model"], r["scene"], r["entry"]) for r in record["single_step"]}
    assert ours >= {(m, s, e) for m, names in scenes.items() for s in names
                    for e in ("step", "in_place")}
    assert {(r["model"], r["copies"]) for r in record["batched"]} >= {
        (m, n) for m in scenes for n in (1, 4)}
    assert {(r["model"], r["substeps"]) for r in record["substeps"]} == {
        (m, k) for m in scenes for k in (1, 3)}
    assert all(r["substeps"] >= 2 for r in record["per_scene"] if r["model"] != "mujoco")
    assert [(r["shortcut"], r["model"], r["scene"]) for r in record["shortcuts"]] == [
        (c.shortcut, c.model, c.scene) for c in cases]
    for row in record["shortcuts"]:  # an exact shortcut changes no state, to the bit
        assert row["max_state_difference"] == (None if row["shortcut"] == "no_solve" else 0.0)
        assert row["speedup"] > 0.0
    assert record["brake_stop"]["ours"]["steps"] == 1
    assert [t["target"].split(",")[0] for t in record["targets"]] == [
        "manipulator", "manipulator", "diff-drive", "diff-drive"]
    assert [t["measured"] is None for t in record["targets"]] == [False, False, True, True]
    for name in ("engine_batched.png", "engine_single_step.png", "engine_shortcuts.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert "**Targets**" in text and "diff-drive, batched" in text


def test_control_study_plays_the_lqr_on_every_task(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(control, "SCALES", (0.01,))
    text = control.run(True, tmp_path, ["lqr"])
    record = load(tmp_path / "control.json")
    assert [(r["controller"], r["task"]) for r in record["records"]] == [
        ("lqr", task) for task in control.TASKS]
    for row in record["records"]:
        assert row["starts"] == control.QUICK_STARTS and row["steps"] > 0
        assert 0.0 <= row["success_rate"] <= 1.0 and 0.0 < row["rtf_median"] <= row["rtf_worst"]
    assert len(record["targets"]) == 3 * len(control.TASKS)
    assert (tmp_path / "control.png").stat().st_size > 0 and "Controllers" in text


def test_headline_collects_every_target(tmp_path: Path) -> None:
    check = report.target_row("a check", "≤", 1.0, "µs", 0.5)
    (tmp_path / "envs.json").write_text(json.dumps({"targets": [check]}))
    (tmp_path / "engine.json").write_text(json.dumps({
        "targets": [{**check, "measured": 2.0, "met": False}],
        "batched": [{"model": "manipulator", "copies": 64, "per_copy_step_s": 1e-7},
                    {"model": "mujoco", "copies": 64, "per_copy_step_s": 5e-7},
                    {"model": "manipulator", "copies": 4, "per_copy_step_s": 9e-7}],
        "brake_stop": {"ours": {"steps": 1}, "mujoco_default": {"steps": 40}}}))
    (tmp_path / "stress.json").write_text(json.dumps({"targets": [stress.target([
        {"name": "one", "passed": True}, {"name": "two", "passed": False}])]}))
    text = report.write_headline(tmp_path)
    rows = load(tmp_path / "headline.json")["rows"]
    assert [(r["benchmark"], r["met"]) for r in rows] == [
        ("engine", False), ("engine", True), ("engine", True), ("envs", True), ("stress", False)]
    assert rows[1]["measured"] == pytest.approx(5.0) and "N = 64" in rows[1]["target"]
    assert rows[4]["note"] == "failed: two"
    assert (rows[4]["measured"], rows[4]["threshold"]) == (1, 2)
    assert text == (tmp_path / "headline.md").read_text().strip() and "| ✗ " in text
    (tmp_path / "empty").mkdir()
    assert report.write_headline(tmp_path / "empty").startswith("no benchmark results")
