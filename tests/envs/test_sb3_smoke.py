"""SB3 PPO and SAC train on both mission envs with the default action space (600 steps).

600 steps pass an episode end of each (500 and 200 steps) and several PPO rollouts and updates
(128-step rollouts) or SAC updates (after 100 random steps, one per 4 steps).
"""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

import mdi_envs  # noqa: F401 - registers the ids

MISSION_ENVS = ["mdi_envs/BlockableManipulator-v0", "mdi_envs/DiffDriveRobot-v0"]


@pytest.mark.slow
@pytest.mark.parametrize("env_id", MISSION_ENVS)
@pytest.mark.parametrize("algorithm", ["PPO", "SAC"])
def test_sb3_trains_600_steps(env_id: str, algorithm: str) -> None:
    import stable_baselines3
    import torch

    torch.set_num_threads(1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(env_id)
    kwargs = {"n_steps": 128, "batch_size": 64} if algorithm == "PPO" else {
        "learning_starts": 100, "batch_size": 64, "train_freq": 4}
    model = getattr(stable_baselines3, algorithm)("MlpPolicy", env, seed=0, device="cpu",
                                                  policy_kwargs={"net_arch": [32, 32]}, **kwargs)
    model.learn(total_timesteps=600)
    assert model.num_timesteps >= 600 and len(model.ep_info_buffer) >= 1  # an episode ended
    obs, _ = env.reset(seed=1)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action) and np.isfinite(action).all()
