"""``mdi-envs demo``: the environments, the optimal references and how RL compares with them.

1. Every registered environment made with ``gym.make``: its action and observation spaces and
   the outcome of one random episode.
2. Every shipped optimal reference (``optimal/references``) replayed open loop through its env,
   saved as ``NAME.gif``.
3. The committed RL vs MPC vs optimal table (``baselines/comparison/compare.md``, written by
   ``mdi-envs compare all`` from ``baselines/comparison/*.json``), then, live, for each
   reference's env and objective the trained policy of each algorithm in ``baselines/trained`` that
   scored best in its own evaluation, played from the nominal start (the best of them saved as
   ``ENV_OBJECTIVE_ALGO_seedS.gif``), its time and effort beside the reference's.

The solver timings and the manipulator under the paper's brake schedule are benchmarks:
``mdi-envs bench solvers`` and ``mdi-envs bench precision``.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import gymnasium as gym
import numpy as np

from mdi_envs import ENV_IDS
from mdi_envs.rendering import save_animation
from mdi_envs.rollout import Rollout, open_loop_policy, rollout
from optimal import available_references, load_reference
from optimal.replay import env_actions, env_options

if TYPE_CHECKING:
    from baselines.train import TrainingRecord

COMPARISON_TABLE = Path(__file__).parent / "comparison" / "compare.md"
"""The committed comparison table (``mdi-envs compare all --output baselines/comparison``)."""

TRAINED_DIR = Path(__file__).parent / "trained"
"""The shipped policies: one ``STEM.json`` (``TrainingRecord``) beside each ``STEM.zip``."""


def run_demo(output: Path) -> list[Path]:
    """Print the three parts to stdout and write the GIFs into ``output``; returns their paths."""
    output.mkdir(parents=True, exist_ok=True)
    print("== The environments (gym.make, one random episode each)")
    for env_id in ENV_IDS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            env = gym.make(env_id)
        print(f"{env_id}\n  action space {env.action_space}\n  observation space "
              f"{env.observation_space}")
        env.close()
        print(f"  random policy: {_outcome(rollout(env_id, 'random'))}")
    written = []
    optimum: dict[tuple[str, str], Rollout] = {}
    print("\n== The optimal references, replayed open loop in their env")
    for name in available_references():
        reference = load_reference(name)
        env_id, options = reference.metadata["env_id"], env_options(reference)
        result = rollout(env_id, open_loop_policy(env_actions(reference)), record=True,
                         **options)  # fmt: skip
        optimum[env_id, options.get("objective", "time")] = result
        print(f"{name} ({env_id}): {_outcome(result)}")
        written.append(save_animation(result.frames[::2], output / f"{name}.gif", fps=15))
    print(f"\n== RL vs MPC vs optimal ({COMPARISON_TABLE.relative_to(Path(__file__).parents[1])})")
    print(COMPARISON_TABLE.read_text())
    print("== Live: the best-evaluated trained policy of each algorithm, nominal start")
    for (env_id, objective), reference in optimum.items():
        played = [(_play(config), config) for config in _best_policies(env_id, objective)]
        ref_time, ref_effort = (reference.last_info[key] for key in ("elapsed_time", "effort"))
        for result, config in played:
            info = result.last_info
            print(f"{env_id} ({objective}) {config.algo} seed {config.seed}: "
                  f"{_outcome(result)}; time / optimal {info['elapsed_time'] / ref_time:.2f}, "
                  f"effort / optimal {info['effort'] / ref_effort:.2f}")
        if played:
            best = min(played, key=lambda pair: (not pair[0].last_info["is_success"],
                                                 pair[0].last_info["elapsed_time"]))[1]
            stem = f"{env_id.split('/')[-1]}_{objective}_{best.algo}_seed{best.seed}"
            frames = _play(best, record_frames=True).frames[::2]
            written.append(save_animation(frames, output / f"{stem}.gif", fps=15))
    return written


def _best_policies(env_id: str, objective: str) -> list[TrainingRecord]:
    """Per algorithm, the record of the shipped policy evaluated best.

    Best: the highest success rate, then the shortest mean elapsed time.
    """
    from baselines.train import read_training

    best: dict[str, TrainingRecord] = {}

    def score(record: TrainingRecord) -> tuple[float, float]:
        evaluation = record.evaluation
        return -(evaluation.success_rate or 0.0), evaluation.mean_elapsed_time or np.inf

    for path in sorted(TRAINED_DIR.glob("*.json")):
        record = read_training(path)
        if (record.env_id, record.objective) == (env_id, objective) and (
                record.algo not in best or score(record) < score(best[record.algo])):
            best[record.algo] = record
    return list(best.values())


def _play(record: TrainingRecord, record_frames: bool = False) -> Rollout:
    """One deterministic episode of a shipped policy from the nominal start."""
    from baselines.train import load_trained, run_name

    stem = run_name(record.env_id, record.objective, record.algo, record.seed)
    model = load_trained(record.algo, TRAINED_DIR / f"{stem}.zip")
    env_kwargs = {**record.env_kwargs, "reset_noise_scale": 0.0}
    return rollout(record.env_id, lambda obs: model.predict(obs, deterministic=True)[0],
                   record=record_frames, **env_kwargs)  # fmt: skip


def _outcome(result: Rollout) -> str:
    info = result.last_info
    return (f"{result.num_steps} steps, success {info.get('is_success')}, elapsed "
            f"{info.get('elapsed_time', 0.0):.3f} s, effort {info.get('effort', 0.0):.4g} "
            "N^2 m^2 s")


__all__ = ["COMPARISON_TABLE", "TRAINED_DIR", "run_demo"]
