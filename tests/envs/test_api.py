"""The Gymnasium and SB3 contracts, for every registered ``mdi_envs/...`` id.

Both env checkers; identical rollouts for a seed; the batched vector env equal to a
``SyncVectorEnv`` of the single env step for step through autoresets; pickling and
``SubprocVecEnv``; rendering; bad actions rejected, out-of-range actions clipped.
"""

from __future__ import annotations

import pickle
import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mdi_envs
from mdi_envs.envs.base import BASE_INFO_KEYS

ENV_IDS = mdi_envs.ENV_IDS


def make(env_id: str, **kwargs: Any) -> gym.Env[Any, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the checker's warnings about unbounded Boxes
        return gym.make(env_id, **kwargs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_check_env(env_id: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(gym.make(env_id).unwrapped, skip_render_check=True)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_sb3_check_env(env_id: str) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sb3_check_env(gym.make(env_id), warn=False)


def rollout(env: gym.Env[Any, Any], seed: int, num_steps: int) -> list[Any]:
    env.action_space.seed(seed)
    obs, _ = env.reset(seed=seed)
    trace = [obs]
    for _ in range(num_steps):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        trace += [obs, reward, terminated, truncated, sorted(info.items())]
        if terminated or truncated:
            trace.append(env.reset()[0])
    return trace


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_rollout(env_id: str) -> None:
    first = rollout(make(env_id), 3, 120)
    second = rollout(make(env_id), 3, 120)
    other = rollout(make(env_id), 4, 120)
    assert repr(first) == repr(second)
    assert repr(first) != repr(other)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_env_equals_sync_vector_env(env_id: str) -> None:
    """400 random steps of 3 copies with episodes of 40 steps (autoresets) or shorter."""
    num_envs, max_steps = 3, 40
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        batched = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                               max_episode_steps=max_steps)  # fmt: skip
        sync = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="sync",
                            max_episode_steps=max_steps)  # fmt: skip
    assert type(batched).__name__.endswith("VectorEnv") and "Sync" not in type(batched).__name__
    obs_b, _ = batched.reset(seed=11)
    obs_s, _ = sync.reset(seed=11)
    np.testing.assert_array_equal(obs_b, obs_s)
    batched.action_space.seed(5)
    num_resets = 0
    for _ in range(400):
        actions = batched.action_space.sample()
        obs_b, reward_b, term_b, trunc_b, info_b = batched.step(actions)
        obs_s, reward_s, term_s, trunc_s, info_s = sync.step(actions)
        np.testing.assert_array_equal(obs_b, obs_s)
        np.testing.assert_array_equal(reward_b, reward_s)
        np.testing.assert_array_equal(term_b, term_s)
        np.testing.assert_array_equal(trunc_b, trunc_s)
        for key in BASE_INFO_KEYS:
            mask = info_s.get("_" + key, np.zeros(num_envs, bool))
            np.testing.assert_array_equal(info_b["_" + key], mask)
            if mask.any():
                np.testing.assert_array_equal(info_b[key][mask], info_s[key][mask])
        num_resets += int(np.sum(term_b | trunc_b))
    assert num_resets >= 3 * (400 // max_steps) - 3


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_pickled_env_continues_identically(env_id: str) -> None:
    env = make(env_id)
    env.reset(seed=1)
    env.action_space.seed(1)
    for _ in range(5):
        env.step(env.action_space.sample())
    clone = pickle.loads(pickle.dumps(env))
    action = env.action_space.sample()
    np.testing.assert_array_equal(env.step(action)[0], clone.step(action)[0])
    np.testing.assert_array_equal(clone.unwrapped.q, env.unwrapped.q)  # views kept live


@pytest.mark.parametrize("env_id", ENV_IDS[:2])
def test_sb3_subproc_vec_env_runs(env_id: str) -> None:
    from stable_baselines3.common.vec_env import SubprocVecEnv

    vec = SubprocVecEnv([lambda: make(env_id) for _ in range(2)], start_method="fork")
    try:
        obs = vec.reset()
        for _ in range(5):
            obs, rewards, dones, infos = vec.step(
                np.stack([vec.action_space.sample() for _ in range(2)]))
        assert obs.shape == (2, *vec.observation_space.shape)
        assert np.isfinite(rewards).all() and len(infos) == 2
    finally:
        vec.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_array_render(env_id: str) -> None:
    env = make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 2
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_action_is_rejected(env_id: str, bad: float) -> None:
    """The step raises and leaves the state (torques included) as it was."""
    env = make(env_id)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    before = env.unwrapped.state.buffer.copy()
    action = np.zeros(env.action_space.shape, np.float32)
    action[0] = bad
    with pytest.raises(ValueError, match="NaN or inf"):
        env.unwrapped.step(action)
    np.testing.assert_array_equal(env.unwrapped.state.buffer, before)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_non_finite_action_of_one_copy_rejects_the_vector_step(env_id: str) -> None:
    """A NaN in the last copy's action raises before any copy's state changes."""
    envs = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    envs.reset(seed=0)
    before = envs.unwrapped.state.buffer.copy()
    actions = np.zeros(envs.action_space.shape, np.float32)
    actions[-1, -1] = np.nan
    with pytest.raises(ValueError, match="NaN or inf"):
        envs.step(actions)
    np.testing.assert_array_equal(envs.unwrapped.state.buffer, before)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_wrong_shape_action_is_rejected(env_id: str) -> None:
    env = make(env_id)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.unwrapped.step(np.zeros(env.action_space.shape[0] + 1, np.float32))


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("num_envs, copies", [(1, (2,)), (1, (1, 1)), (3, (2,)), (3, (4,))])
def test_action_of_the_wrong_count_or_rank_is_rejected(
    env_id: str, num_envs: int, copies: tuple[int, ...]
) -> None:
    """The wrong number of copies (or rank) with the right last axis is rejected unchanged.

    Such an array goes to the compiled step as it is: the step raises, naming the shape.
    """
    envs = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point")
    envs.reset(seed=0)
    before = envs.unwrapped.state.buffer.copy()
    with pytest.raises(ValueError, match="shape"):
        envs.step(np.zeros((*copies, envs.single_action_space.shape[0]), np.float32))
    np.testing.assert_array_equal(envs.unwrapped.state.buffer, before)

@pytest.mark.parametrize("env_id", ENV_IDS)
def test_out_of_range_action_is_clipped(env_id: str) -> None:
    """An action of 5 everywhere does what an action of 1 does."""
    results = []
    for scale in (5.0, 1.0):
        env = make(env_id)
        env.reset(seed=0)
        for _ in range(5):
            obs = env.step(np.full(env.action_space.shape, scale, np.float32))[0]
        results.append(obs)
    np.testing.assert_array_equal(results[0], results[1])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_start_state_is_the_nominal_one_plus_uniform_noise(env_id: str) -> None:
    """reset(seed=s) draws Generator(s).uniform(-scale, scale) onto the noisy entries only."""
    scale = 0.05
    env = make(env_id, reset_noise_scale=scale)
    env.reset(seed=7)
    scene = env.unwrapped.scene
    entries = list(scene.START_NOISE_ENTRIES)
    expected = scene.nominal_start()
    expected[entries] += gym.utils.seeding.np_random(7)[0].uniform(-scale, scale, len(entries))
    state = env.unwrapped.state
    np.testing.assert_array_equal(np.concatenate([state.q[0], state.u[0]]), expected)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_step_before_reset_is_an_error(env_id: str) -> None:
    env = make(env_id).unwrapped
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros(env.action_space.shape, np.float32))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_info_has_every_documented_key(env_id: str) -> None:
    env = make(env_id)
    env.reset(seed=0)
    reward, info = env.step(env.action_space.sample())[1::3]
    assert set(BASE_INFO_KEYS) <= set(info)
    assert isinstance(info["is_success"], bool) and isinstance(info["solver_status"], int)
    assert info["elapsed_time"] == pytest.approx(env.unwrapped.dt)
    terms = info["reward_objective"] + info["reward_shaping"] + info["reward_goal"]
    assert reward == pytest.approx(terms, rel=1e-15, abs=1e-15)
    assert info["solver_status"] == 0


@pytest.mark.parametrize("env_id", ENV_IDS[:1])
def test_partial_reset_matches_sync_vector_env(env_id: str) -> None:
    """``reset(options={"reset_mask": ...})`` resets only the masked copies, as Sync does."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        envs = [gym.make_vec(env_id, num_envs=3, vectorization_mode=mode)
                for mode in ("vector_entry_point", "sync")]
    for env in envs:
        env.reset(seed=2)
    envs[0].action_space.seed(0)
    mask = np.array([True, False, True])
    for step in range(60):
        actions = envs[0].action_space.sample()
        results = [env.step(actions)[:4] for env in envs]
        if step == 30:
            results = [env.reset(options={"reset_mask": mask.copy()}) for env in envs]
        np.testing.assert_array_equal(results[0][0], results[1][0])
        np.testing.assert_array_equal(results[0][1], results[1][1])
    with pytest.raises(ValueError, match="reset_mask"):
        envs[0].reset(options={"reset_mask": np.zeros(3, bool)})


def test_unseeded_reset_continues_each_copys_stream_like_sync() -> None:
    env_id = ENV_IDS[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        envs = [gym.make_vec(env_id, num_envs=2, vectorization_mode=mode)
                for mode in ("vector_entry_point", "sync")]
    first = [env.reset(seed=7)[0] for env in envs]
    second = [env.reset()[0] for env in envs]
    np.testing.assert_array_equal(first[0], first[1])
    np.testing.assert_array_equal(second[0], second[1])
    assert not np.array_equal(first[0], second[0])


@pytest.mark.parametrize(("env_id", "objective", "shaping_discount", "goal_weight"), [
    ("mdi_envs/BlockableManipulator-v0", "time", 0.99, 10.0),
    ("mdi_envs/BlockableManipulator-v1", "time", 1.0, 10.0),
    ("mdi_envs/DiffDriveRobot-v0", "time", 0.99, 10.0),
    ("mdi_envs/DiffDriveRobot-v1", "time", 1.0, 10.0),
    ("mdi_envs/DiffDriveRobotEffort-v1", "effort", 1.0, 1000.0),
])
def test_each_id_makes_its_version_of_the_task(env_id: str, objective: str,
                                               shaping_discount: float,
                                               goal_weight: float) -> None:  # fmt: skip
    """The id alone sets the task (single and vector env); arguments still override it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scenes = [make(env_id).unwrapped.scene, gym.make_vec(env_id, num_envs=2).scene]
    for scene in scenes:
        assert (scene.objective, scene.shaping_discount, scene.goal_weight) == (
            objective, shaping_discount, goal_weight)
    assert make(env_id, shaping_discount=0.5).unwrapped.scene.shaping_discount == 0.5
