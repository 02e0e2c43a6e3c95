"""Tests of the environment benchmark (``benchmarks/envs.py``) at a minimal size.

The fast test runs every part of the benchmark on Gymnasium's CartPole-v1 (which has a vector
entry point) in place of our environments, so it takes seconds; the slow one runs it on the
manipulator, whose first step compiles the numba kernels (tens of seconds in a fresh process).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from benchmarks.envs import EnvsConfig, run
from benchmarks.timing import TimingPlan

COUNTS = (".episodes_ended",)
"""Counters that may be 0; every other number in the record must be > 0."""
TINY_PLAN = TimingPlan(budget_s=0.01, min_rounds=3, max_rounds=3, min_batch_s=5e-4)


def tiny_config(env_ids: tuple[str, ...], peers: tuple[str, ...]) -> EnvsConfig:
    return EnvsConfig(env_ids=env_ids, peers=peers, sync_peer="Acrobot-v1", sync_max_copies=4,
                      copies=(1, 4), action_samples=32, step_plan=TINY_PLAN,
                      vector_plan=TINY_PLAN, cpu=None)


def numbers(value: Any, path: str = "") -> list[tuple[str, float]]:
    """Every int/float in a JSON tree (bools excluded), with its path."""
    if isinstance(value, bool) or value is None:
        return []
    if isinstance(value, (int, float)):
        return [(path, float(value))]
    if isinstance(value, dict):
        return [item for k, v in value.items() for item in numbers(v, f"{path}.{k}")]
    if isinstance(value, list):
        return [item for i, v in enumerate(value) for item in numbers(v, f"{path}[{i}]")]
    return []


def check_record(output: Path, report: str, ours: tuple[str, ...]) -> dict[str, Any]:
    for name in ("envs.json", "envs_step.png", "envs_vector.png"):
        assert (output / name).stat().st_size > 0, name
    record = json.loads((output / "envs.json").read_text())
    for key in ("machine", "pinning", "config", "units", "single_env", "vector_env", "targets",
                "notes", "unavailable"):
        assert key in record, key
    for key in ("cpu_model", "cpu_count", "python", "versions"):
        assert key in record["machine"], key
    for package in ("numpy", "numba", "gymnasium", "mujoco"):
        assert package in record["machine"]["versions"], package
    single = {r["env_id"]: r for r in record["single_env"]}
    assert set(ours) | {"Acrobot-v1"} <= set(single)
    for r in single.values():
        assert r["frame_skip"] >= 1
        for entry in ("gym.make", "unwrapped"):
            timing = r[entry]
            assert timing["min_us"] <= timing["median_us"]
            assert timing["steps_total"] > 0
    for env_id in ours:
        assert single[env_id]["ours"]
        assert single[env_id]["ratios"]["Acrobot-v1"]["ratio_median"] > 0
    vector = {(r["env_id"], r["mode"], r["num_envs"]) for r in record["vector_env"]}
    for n in (1, 4):
        assert ("Acrobot-v1", "sync", n) in vector
        for env_id in ours:
            assert (env_id, "vector_entry_point", n) in vector
    for r in record["vector_env"]:
        assert r["physics_steps_per_s"] == pytest.approx(r["env_steps_per_s"] * r["frame_skip"])
    for key in ("single_env", "vector_env"):
        values = numbers(record[key])
        assert values
        for path, value in values:
            assert math.isfinite(value), (key + path, value)
            if path.endswith(COUNTS):  # may be 0 in a short run
                assert value >= 0, (key + path, value)
            else:
                assert value > 0, (key + path, value)
    for t in record["targets"]:
        assert t["met"] in (True, False, None)
        if t["measured"] is not None:
            assert math.isfinite(t["measured"]) and t["measured"] > 0
    assert "**Targets**" in report and report.startswith("Run ")
    return record


def test_envs_benchmark_minimal(tmp_path: Path) -> None:
    ours = ("CartPole-v1",)
    report = run(tiny_config(ours, ("Acrobot-v1", "NoSuchEnv-v0")), tmp_path, quick=True,
                 log=lambda message: None)
    record = check_record(tmp_path, report, ours)
    assert [u["env_id"] for u in record["unavailable"]] == ["NoSuchEnv-v0"]
    assert any("NoSuchEnv-v0" in note for note in record["notes"])


@pytest.mark.slow
def test_envs_benchmark_manipulator(tmp_path: Path) -> None:
    ours = ("mdi_envs/BlockableManipulator-v0",)
    report = run(tiny_config(ours, ("Acrobot-v1",)), tmp_path, quick=True,
                 log=lambda message: None)
    record = check_record(tmp_path, report, ours)
    assert record["single_env"][0]["frame_skip"] == 2
    assert record["targets"][0]["measured"] is not None
