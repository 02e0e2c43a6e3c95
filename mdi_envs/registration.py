"""Every environment id, registered in one place with lazy string entry points."""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

_ENVS = {
    # id: (module, class prefix, max_episode_steps)
    "mdi_envs/BlockableManipulator-v0": ("blockable_manipulator", "BlockableManipulator", 500),
    "mdi_envs/DiffDriveRobot-v0": ("diff_drive", "DiffDriveRobot", 200),
    "mdi_envs/BouncingBall-v0": ("bouncing_ball", "BouncingBall", 600),
    "mdi_envs/SlidingBlock-v0": ("sliding_block", "SlidingBlock", 500),
}
ENV_IDS = tuple(_ENVS)


def register_envs() -> None:
    """Register the ``mdi_envs/...`` ids (idempotent)."""
    for env_id, (module, prefix, max_episode_steps) in _ENVS.items():
        if env_id in registry:
            continue
        register(
            id=env_id,
            entry_point=f"mdi_envs.envs.{module}:{prefix}Env",
            vector_entry_point=f"mdi_envs.envs.{module}:{prefix}VectorEnv",
            max_episode_steps=max_episode_steps,
            # The envs check reset-before-step and every action themselves (ResetNeeded,
            # ValueError): Gymnasium's OrderEnforcing and passive checker wrappers would only
            # repeat that, at ~1-2 us per step each.
            order_enforce=False,
            disable_env_checker=True,
        )


__all__ = ["ENV_IDS", "register_envs"]
