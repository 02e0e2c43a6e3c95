"""Write the small GIFs of the README and the env pages: ``docs/assets/<Name>-vN.gif``.

``python docs/make_gifs.py [ENV_ID ...]`` (default: every registered ``mdi_envs/`` id). An id
with a shipped optimal reference replays the reference's controls open loop; the others play
zero actions (the passive dynamics: the ball's Zeno bounces, the block's slide and stick).
Frames are halved in size and every second one kept; about a minute per id with a warm
kernel cache.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
from PIL import Image

import mdi_envs  # noqa: F401  (registers the ids)
from mdi_envs.rendering import save_animation
from mdi_envs.rollout import open_loop_policy, rollout
from optimal import available_references, load_reference
from optimal.replay import env_actions, env_options

ASSETS = Path(__file__).resolve().parent / "assets"
MAX_STEPS = 300
"""Longest episode shown [env steps]."""


def frames_for(env_id: str) -> list[np.ndarray]:
    """The recorded frames of one episode of ``env_id``."""
    for name in available_references():
        reference = load_reference(name)
        if reference.metadata["env_id"] == env_id:
            result = rollout(env_id, open_loop_policy(env_actions(reference)), record=True,
                             max_steps=MAX_STEPS, **env_options(reference))
            return result.frames
    zeros = np.zeros(gym.spec(env_id).make().action_space.shape, dtype=np.float32)
    return rollout(env_id, lambda _obs: zeros, record=True, max_steps=MAX_STEPS).frames


def main(argv: list[str]) -> int:
    """Write one GIF per id."""
    ids = argv or sorted(i for i in gym.registry if i.startswith("mdi_envs/"))
    ASSETS.mkdir(exist_ok=True)
    for env_id in ids:
        frames = frames_for(env_id)[::2]
        small = [np.asarray(Image.fromarray(f).reduce(2)) for f in frames]
        path = save_animation(small, ASSETS / f"{env_id.removeprefix('mdi_envs/')}.gif", fps=15)
        print(f"wrote {path} ({path.stat().st_size // 1024} kB, {len(small)} frames)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
