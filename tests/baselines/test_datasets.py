"""Minari datasets of the experts: written, read back with minari.load_dataset, and replayable."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("minari", reason="minari is in the datasets extra")
import minari  # noqa: E402

from baselines.datasets import build_dataset, dataset_id  # noqa: E402
from baselines.evaluation import DIFF_DRIVE_EFFORT_V1, MANIPULATOR_V1  # noqa: E402
from optimal.references import load_reference  # noqa: E402
from optimal.replay import env_actions  # noqa: E402


@pytest.fixture(autouse=True)
def datasets_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path))
    return tmp_path


def test_the_optimum_is_one_episode_of_its_controls() -> None:
    build_dataset(MANIPULATOR_V1, "optimal")
    dataset = minari.load_dataset("mdi_envs/BlockableManipulator/optimal-v0")
    (episode,) = list(dataset.iterate_episodes())
    actions = env_actions(load_reference("manipulator_time"))
    steps = len(episode.actions)
    # the env ends the episode once inside the goal box: at the reference's last step or before
    assert len(actions) - 3 <= steps <= len(actions)
    np.testing.assert_allclose(episode.actions, actions[:steps], rtol=1e-6)
    assert episode.terminations[-1] and not episode.terminations[:-1].any()
    assert episode.observations.shape == (steps + 1, 7)


def test_an_expert_dataset_replays_in_its_recovered_env() -> None:
    built = build_dataset(DIFF_DRIVE_EFFORT_V1, "lqr", num_episodes=2, scale=0.01, first_seed=5)
    dataset = minari.load_dataset(dataset_id(DIFF_DRIVE_EFFORT_V1, "lqr"))
    assert dataset.total_episodes == built.total_episodes == 2
    env = dataset.recover_environment()
    assert env.spec.kwargs["reset_noise_scale"] == 0.01
    for seed, episode in zip((5, 6), dataset.iterate_episodes(), strict=True):
        observation, _ = env.reset(seed=seed)
        np.testing.assert_array_equal(observation, episode.observations[0])
        for t, action in enumerate(episode.actions):  # the env is deterministic given the seed
            observation, reward, terminated, truncated, _ = env.step(action)
            np.testing.assert_array_equal(observation, episode.observations[t + 1])
            assert reward == pytest.approx(episode.rewards[t], rel=1e-6)
            assert (terminated, truncated) == (episode.terminations[t], episode.truncations[t])
        assert terminated or truncated


def test_bad_requests_name_the_problem() -> None:
    with pytest.raises(ValueError, match="no dataset task"):
        build_dataset("mdi_envs/BlockableManipulator-v0")
    with pytest.raises(ValueError, match="unknown expert"):
        build_dataset(MANIPULATOR_V1, "oracle")
    with pytest.raises(ValueError, match="num_episodes"):
        build_dataset(MANIPULATOR_V1, "lqr", num_episodes=0)
