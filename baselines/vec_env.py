"""An SB3 ``VecEnv`` over one batched ``MoreauJeanVectorEnv`` (all copies in one compiled call).

Stable-Baselines3 expects a vector env that resets a finished copy within the same step: the
observation it returns is the new episode's first one, and the last observation of the finished
episode travels in ``infos[i]["terminal_observation"]``. The Gymnasium vector envs of
``mdi_envs`` autoreset on the *next* step instead (``AutoresetMode.NEXT_STEP``). The adapter
bridges the two: after each step it resets the copies that ended through
``reset(options={"reset_mask": done})``, which also clears their pending next-step reset, so
the wrapped env never takes an autoreset step. The result equals SB3's ``DummyVecEnv`` over
``gym.make`` copies seeded alike, step for step (``tests/baselines/test_vec_env.py``).
``TimeAwareVecEnv`` appends each copy's elapsed time to its observations, the batched form of
``baselines.time_input``'s input.

Example::

    import gymnasium as gym, mdi_envs
    from stable_baselines3.common.vec_env import VecMonitor
    from baselines.vec_env import MoreauJeanVecEnv, make_vec_env

    venv = VecMonitor(make_vec_env("mdi_envs/DiffDriveRobot-v0", num_envs=64, objective="effort"))
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env.base_vec_env import (
    VecEnv,
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
    VecEnvWrapper,
)

import mdi_envs  # noqa: F401 - registers the ids


def make_vec_env(env_id: str, num_envs: int, **env_kwargs: Any) -> MoreauJeanVecEnv:
    """``MoreauJeanVecEnv`` over ``gym.make_vec(env_id, num_envs, "vector_entry_point")``.

    Args:
        env_id: a registered ``mdi_envs/...`` id.
        num_envs: the number of copies N.
        **env_kwargs: environment arguments (e.g. ``objective="effort"``, ``shaping_discount``).
    """
    venv = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                        **env_kwargs)  # fmt: skip
    return MoreauJeanVecEnv(venv)


class MoreauJeanVecEnv(VecEnv):
    """SB3 ``VecEnv`` adapter of a batched Gymnasium vector env of ``mdi_envs``.

    Observations are returned as the wrapped env's (N, obs_dim) float32 array, rewards as (N,)
    float32 (as ``DummyVecEnv``), dones as (N,) bool = terminated | truncated. ``infos`` is a
    list of N dicts holding the step's info entries as Python scalars (``is_success``,
    ``elapsed_time`` [s], ``effort`` [N^2 m^2 s], reward terms, solver diagnostics, ...); on a
    done step also ``terminal_observation`` (obs_dim,) and ``TimeLimit.truncated`` (truncated
    and not terminated).

    Seeding follows SB3: ``seed(s)`` gives copy i the seed s + i at the next ``reset()``; a copy
    reset after its episode ends continues its own random stream (as ``gym.Env.reset()``).

    The copies share one scene object, so ``get_attr``/``set_attr``/``env_method`` act on the
    wrapped vector env (a read returns its value once per requested index); ``env_is_wrapped``
    is False for every copy (there are no per-copy wrappers).

    Args:
        venv: a vector env from ``gym.make_vec(..., vectorization_mode="vector_entry_point")``
            (a ``MoreauJeanVectorEnv``, whose ``reset`` accepts ``options={"reset_mask": m}``).
    """

    def __init__(self, venv: gym.vector.VectorEnv) -> None:
        self.venv = venv
        self._actions: np.ndarray | None = None
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self.metadata = {**self.metadata, **getattr(venv, "metadata", {})}

    # -- core API ---------------------------------------------------------------------------
    def reset(self) -> VecEnvObs:
        """Reset every copy (with the seeds and options set by ``seed``/``set_options``)."""
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        options = self._options[0] if self._options and self._options[0] else None
        obs, _ = self.venv.reset(seed=seeds, options=options)  # type: ignore[arg-type]
        self.reset_infos = [{} for _ in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return np.asarray(obs).copy()

    def step_async(self, actions: Any) -> None:
        """Store the actions for ``step_wait``: (N, action_dim) for a Box action space.

        For a Tuple action space (``action_mode="hybrid"``) either a list of N per-copy tuples
        (SB3's layout, as ``DummyVecEnv`` takes; stacked here) or one tuple of batched
        components (Gymnasium's ``batch_space`` layout, e.g. (choices (N,), torques (N, m))).
        """
        if isinstance(self.action_space, spaces.Tuple) and not isinstance(actions, tuple):
            actions = tuple(np.stack([np.asarray(action[j]) for action in actions])
                            for j in range(len(self.action_space.spaces)))  # fmt: skip
        self._actions = actions

    def step_wait(self) -> VecEnvStepReturn:
        """Step every copy; reset the copies that ended so their new first obs is returned.

        Returns:
            obs (N, obs_dim) float32, rewards (N,) float32, dones (N,) bool, infos (N dicts).
        """
        if self._actions is None:
            raise RuntimeError("step_wait() called without step_async()")
        obs, reward, terminated, truncated, info = self.venv.step(self._actions)
        self._actions = None
        obs = np.array(obs, copy=True)
        terminated = np.asarray(terminated, dtype=bool)
        truncated = np.asarray(truncated, dtype=bool)
        dones = terminated | truncated
        infos = self._split_info(info)
        if dones.any():
            done_indices = np.flatnonzero(dones)
            for i in done_indices:
                infos[i]["terminal_observation"] = obs[i].copy()
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            obs[done_indices] = self._reset_copies(dones)[done_indices]
            for i in done_indices:
                self.reset_infos[i] = {}
        for i in np.flatnonzero(~dones):
            infos[i]["TimeLimit.truncated"] = False
        return obs, np.asarray(reward, dtype=np.float32).copy(), dones, infos

    def _reset_copies(self, mask: np.ndarray) -> np.ndarray:
        """Reset the masked copies, each continuing its own random stream; returns the obs."""
        return np.asarray(self.venv.reset(options={"reset_mask": mask.copy()})[0])

    def _split_info(self, info: dict[str, Any]) -> list[dict[str, Any]]:
        """Per-copy dicts from the vector env's dict of (N,) arrays with ``_key`` masks."""
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for key, values in info.items():
            if key.startswith("_"):
                continue
            mask = info.get("_" + key)
            listed = np.asarray(values).tolist()
            if mask is None:
                for i, value in enumerate(listed):
                    infos[i][key] = value
            else:
                for j in np.flatnonzero(mask).tolist():
                    infos[j][key] = listed[j]
        return infos

    def close(self) -> None:
        """Close the wrapped vector env."""
        self.venv.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        """The vector envs do not render: one None per copy."""
        return [None] * self.num_envs

    # -- attributes and methods (shared by every copy) --------------------------------------
    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """The wrapped vector env's attribute, once per index."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set an attribute of the wrapped vector env (shared: ``indices`` must be all)."""
        if len(self._indices(indices)) != self.num_envs:
            raise ValueError("the copies share one env object: set_attr needs indices=None")
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: VecEnvIndices = None,
                   **method_kwargs: Any) -> list[Any]:  # fmt: skip
        """Call a method of the wrapped vector env once; its result repeated per index."""
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        return [result for _ in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper],
                       indices: VecEnvIndices = None) -> list[bool]:  # fmt: skip
        """False for every copy: the batched env has no per-copy Gymnasium wrappers."""
        return [False for _ in self._indices(indices)]

    def _indices(self, indices: VecEnvIndices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        if isinstance(indices, (int, np.integer)):
            return [int(indices)]
        assert isinstance(indices, Iterable)
        return [int(i) for i in indices]


class TimeAwareVecEnv(VecEnvWrapper):  # type: ignore[misc]
    """A ``VecEnv`` whose (N, d) observations get each copy's ``steps / limit`` appended.

    ``steps`` counts the actions of the copy's episode (0 after its reset), as Gymnasium's
    ``TimeAwareObservation(normalize_time=True)`` and ``baselines.time_input.with_time`` do; a
    done copy's ``terminal_observation`` carries its final count.

    Args:
        venv: the batched env (Box observations, done copies reset within the step).
        limit: the episode's step limit (``baselines.time_input.max_steps`` of one copy).
    """

    def __init__(self, venv: VecEnv, limit: int) -> None:
        space = venv.observation_space
        low = np.append(space.low, 0.0).astype(np.float32)
        high = np.append(space.high, 1.0).astype(np.float32)
        super().__init__(venv, observation_space=spaces.Box(low, high, dtype=np.float32))
        self.limit = int(limit)
        self.steps = np.zeros(venv.num_envs, dtype=np.int64)

    def _with_time(self, observations: np.ndarray) -> np.ndarray:
        return np.column_stack([observations, self.steps / self.limit]).astype(np.float32)

    def reset(self) -> VecEnvObs:
        """Reset every copy: counts 0."""
        self.steps[:] = 0
        return self._with_time(self.venv.reset())

    def step_wait(self) -> VecEnvStepReturn:
        """Step every copy; a done copy's count restarts at 0 with its next episode."""
        observations, rewards, dones, infos = self.venv.step_wait()
        self.steps += 1
        for i in np.flatnonzero(dones):
            final = np.asarray(infos[i]["terminal_observation"], dtype=np.float32)
            elapsed = np.float32(self.steps[i] / self.limit)
            infos[i]["terminal_observation"] = np.append(final, elapsed)
        self.steps[dones] = 0
        return self._with_time(observations), rewards, dones, infos


__all__ = ["MoreauJeanVecEnv", "TimeAwareVecEnv", "make_vec_env"]
