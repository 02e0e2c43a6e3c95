"""Every shipped reference: loads without CasADi, carries its metadata, replays to the goal."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from optimal import available_references, load_reference
from optimal.replay import replay, replay_in_env

SHIPPED = available_references()
METADATA_FIELDS = ("env_id", "env_version", "time_step", "num_intervals", "cost", "final_time",
                   "residual", "replay", "commit", "total_time", "converged")


def test_load_reference_names_the_available_ones() -> None:
    with pytest.raises(FileNotFoundError, match="available"):
        load_reference("no_such_reference")


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_loads_without_casadi(name: str) -> None:
    code = (
        "import sys; sys.modules['casadi'] = None\n"
        "from optimal import load_reference\n"
        f"r = load_reference({name!r})\n"
        "assert r.q.shape[0] == r.tau.shape[0] + 1\n"
        "print(r.final_time)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False)
    assert done.returncode == 0, done.stderr
    assert float(done.stdout) == pytest.approx(load_reference(name).final_time)


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_metadata_and_final_stage(name: str) -> None:
    reference = load_reference(name)
    for key in METADATA_FIELDS:
        assert key in reference.metadata
    assert reference.metadata["converged"]
    assert reference.metadata["residual"] <= 1e-8
    # solved by the continuation (its stages) or found by the global search (its record)
    assert "history" in reference.metadata or "search" in reference.metadata
    assert reference.time_step == pytest.approx(reference.final_time / reference.tau.shape[0])


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_replays_to_the_goal(name: str) -> None:
    reference = load_reference(name)
    report, q, _, _ = replay(reference, substeps=1)
    assert report.reaches_goal, report.goal_errors
    assert report.state_error <= 1e-6
    np.testing.assert_allclose(q[-1], reference.q[-1], atol=1e-6)


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_replays_to_the_goal_in_the_gym_env(name: str) -> None:
    """Open loop through gym.make(env_id): the env's own success test passes at the end."""
    reference = load_reference(name)
    q, info = replay_in_env(reference)
    assert info["is_success"], info
    # the env ends the episode as soon as the state is within its success tolerances: at t_f,
    # or a few steps before it (the manipulator's optimum is within 0.05 rad at 4.185 s)
    steps = round(info["elapsed_time"] / reference.time_step)
    assert info["elapsed_time"] == pytest.approx(steps * reference.time_step, rel=1e-9)
    assert reference.tau.shape[0] - 3 <= steps <= reference.tau.shape[0]
    # the env takes float32 actions (torques rounded to ~6e-8 relative); over the robot's
    # maneuver this moves the wheel angles by up to ~2e-5 rad, the manipulator's by < 1e-6
    atol = 1e-6 if reference.brake_bound is not None else 1e-4
    np.testing.assert_allclose(q, reference.q[steps], atol=atol)


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_is_within_the_shipping_rule_of_its_continuous_optimum(name: str) -> None:
    import json

    pytest.importorskip("casadi")
    from optimal.convergence import CONTINUOUS_DIR, continuous_cost
    from optimal.solve import SHIPPED_LEVEL_CHANGE

    record = json.loads((CONTINUOUS_DIR / f"{name}.json").read_text())
    optimum = continuous_cost(record)
    assert abs(load_reference(name).cost / optimum - 1.0) < SHIPPED_LEVEL_CHANGE
