"""``mdi-envs train ENV_ID ALGO``: train one SB3 baseline with the table's settings.

Wiring (in ``mdi_envs/cli.py``): ``from baselines.cli import add_train_parser`` and call
``add_train_parser(commands)`` on the subparsers; the parser's handler is ``run_train``.
Example: ``mdi-envs train mdi_envs/DiffDriveRobot-v0 PPO --task effort --output
results/baselines`` (3 x 10^6 steps; the budget and settings are in
``baselines/hyperparameters.py``) shows SB3's progress bar on a terminal and writes the model
zip, its JSON config, the episode CSV, the training-curve PNG and TensorBoard logs into
``--output``. ``--timesteps 20000`` gives a run of a minute or two. ``mdi-envs train
mdi_envs/BlockableManipulator-v0 HybridPPO`` trains ``baselines.hybrid_ppo.HybridPPO`` on the
manipulator's native hybrid action space (algorithm names are case-insensitive).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def add_train_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``train`` subcommand to an argparse subparsers object; returns its parser."""
    from baselines.hyperparameters import ALGORITHMS, DEFAULT_TASKS, canonical_algorithm

    parser = subparsers.add_parser(
        "train",
        help="train an SB3 baseline (PPO, SAC or HybridPPO) on a mission environment",
        description="Train ALGO on ENV_ID through the batched vector env with the settings of "
        "baselines/hyperparameters.py (seed, budget and copies overridable), then evaluate it "
        "and save STEM.zip, STEM.json (exact config, versions, commit, scores), "
        "STEM_episodes.csv, STEM.png and TensorBoard logs into --output. Needs the rl extra "
        "(pip install 'mdi-envs[rl]').",
    )
    parser.add_argument("env_id", choices=sorted(DEFAULT_TASKS), help="the environment")
    parser.add_argument("algo", type=canonical_algorithm, choices=ALGORITHMS,
                        help="the algorithm (case-insensitive; HybridPPO: the manipulator's "
                        "hybrid brake x torque action space)")
    parser.add_argument("--task", choices=("time", "effort"), default=None,
                        help="objective (effort: diff drive only; default time)")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: the table's)")
    parser.add_argument("--timesteps", type=int, default=None,
                        help="environment steps over all copies (default: the table's)")
    parser.add_argument("--num-envs", type=int, default=None,
                        help="batched copies (default: the table's)")
    parser.add_argument("--eval-episodes", type=int, default=10,
                        help="deterministic evaluation episodes after training")
    parser.add_argument("--output", type=Path, default=Path("results/baselines"),
                        help="folder for the model, config, curves and TensorBoard logs")
    parser.add_argument("--no-progress-bar", action="store_true",
                        help="hide SB3's progress bar (shown on a terminal by default)")
    parser.set_defaults(handler=run_train)
    return parser


def run_train(args: argparse.Namespace) -> int:
    """Handler of ``train``: trains, prints the saved paths and scores; returns 0."""
    from baselines.train import train

    progress = False if args.no_progress_bar else None
    model_path = train(args.env_id, args.algo, task=args.task, seed=args.seed,
                       total_timesteps=args.timesteps, output=args.output,
                       num_envs=args.num_envs, eval_episodes=args.eval_episodes,
                       progress_bar=progress)  # fmt: skip
    config = json.loads(model_path.with_suffix(".json").read_text())
    evaluation = config["evaluation"]
    print(f"trained {config['algo']} on {config['env_id']} ({config['task']}): "
          f"{config['num_timesteps']} steps in {config['wall_time_s']:.1f} s, "
          f"{config['num_episodes']} episodes")  # fmt: skip
    if evaluation.get("mean_return") is not None:
        print(f"evaluation ({evaluation['episodes']} episodes, deterministic): return "
              f"{evaluation['mean_return']:.3f} +- {evaluation['std_return']:.3f}, success "
              f"{evaluation['success_rate']:.0%}, elapsed {evaluation['mean_elapsed_time']:.3f} "
              f"s, effort {evaluation['mean_effort']:.4g}")  # fmt: skip
    for suffix in (".zip", ".json", ".png"):
        print(f"saved {model_path.with_suffix(suffix)}")
    print(f"TensorBoard: tensorboard --logdir {args.output / 'tensorboard'}")
    return 0


__all__ = ["add_train_parser", "run_train"]
