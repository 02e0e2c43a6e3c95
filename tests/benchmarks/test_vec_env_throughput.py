"""The vec-env throughput benchmark runs end to end on a tiny budget and writes its files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from benchmarks.vec_env_throughput import BACKENDS, main

pytest.importorskip("stable_baselines3", reason="the benchmark needs the rl extra")


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::UserWarning")  # SB3: rollout smaller than the minibatch
def test_every_backend_trains_and_is_recorded(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--num-envs", "2", "--rollouts", "1", "--output", str(tmp_path)]) == 0
    record = json.loads((tmp_path / "vec_env_throughput.json").read_text())
    assert [r["backend"] for r in record["results"]] == list(BACKENDS)
    for result in record["results"]:
        assert result["timesteps"] == 2 * 256  # one rollout of the shipped n_steps
        assert result["train_steps_per_s"] > 0 and 0 < result["rollout_s"] < result["train_s"]
    assert (tmp_path / "vec_env_throughput.png").stat().st_size > 10_000
    lines = capsys.readouterr().out.splitlines()
    assert any(line.startswith("| batched adapter ") for line in lines)
