"""The baselines' subcommands: simulate, demo, train, sweep, compare and robustness.

Each ``add_*_parser`` is registered in ``pyproject.toml`` as a ``mdi_envs.commands`` entry
point (the plug-in interface is in ``mdi_envs/cli.py``); each parser's handler is its ``run_*``
function.
Example: ``mdi-envs train mdi_envs/DiffDriveRobot-v0 PPO --objective effort --output
results/baselines`` (5 x 10^6 steps; the budget and settings are in
``baselines/hyperparams/*.yml``, rl-zoo3's format) shows SB3's progress bar on a terminal and
writes the model zip, its JSON config, the episode CSV, the training-curve PNG and TensorBoard
logs into ``--output``. ``--timesteps 20000`` gives a run of a minute or two. ``mdi-envs train
mdi_envs/BlockableManipulator-v0 HybridPPO`` trains ``baselines.hybrid_ppo.HybridPPO`` on the
manipulator's native hybrid action space (algorithm names are case-insensitive).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from baselines.records import DEFAULT_SCALE

if TYPE_CHECKING:
    from collections.abc import Callable

    from baselines.records import Condition, Study


def add_train_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``train`` subcommand to an argparse subparsers object; returns its parser."""
    from baselines.hyperparameters import ALGORITHMS, DEFAULT_OBJECTIVES, canonical_algorithm

    parser = subparsers.add_parser(
        "train",
        help="train an SB3 baseline (PPO, SAC or HybridPPO) on a mission environment",
        description="Train ALGO on ENV_ID through the batched vector env with the settings of "
        "baselines/hyperparams/*.yml (rl-zoo3's format; seed, budget and copies overridable), "
        "then evaluate it and save STEM.zip, STEM.json (exact config, versions, commit, scores), "
        "STEM_episodes.csv, STEM.png and TensorBoard logs into --output. Needs the rl extra "
        "(pip install 'mdi-envs[rl]').",
    )
    parser.add_argument("env_id", choices=sorted(DEFAULT_OBJECTIVES), help="the environment")
    parser.add_argument("algo", type=canonical_algorithm, choices=ALGORITHMS,
                        help="the algorithm (case-insensitive; HybridPPO: the manipulator's "
                        "hybrid brake x torque action space)")
    parser.add_argument("--objective", choices=("time", "effort"), default=None,
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
    from baselines.train import read_training, train

    progress = False if args.no_progress_bar else None
    model_path = train(args.env_id, args.algo, objective=args.objective, seed=args.seed,
                       total_timesteps=args.timesteps, output=args.output,
                       num_envs=args.num_envs, eval_episodes=args.eval_episodes,
                       progress_bar=progress)  # fmt: skip
    record = read_training(model_path.with_suffix(".json"))
    score = record.evaluation
    print(f"trained {record.algo} on {record.env_id} ({record.objective}): "
          f"{record.num_timesteps} steps in {record.wall_time_s:.1f} s, "
          f"{record.num_episodes} episodes")  # fmt: skip
    if score.mean_return is not None:
        print(f"evaluation ({score.episodes} episodes, deterministic): return "
              f"{score.mean_return:.3f} +- {score.std_return:.3f}, success "
              f"{score.success_rate:.0%}, elapsed {score.mean_elapsed_time:.3f} "
              f"s, effort {score.mean_effort:.4g}")  # fmt: skip
    for suffix in (".zip", ".json", ".png"):
        print(f"saved {model_path.with_suffix(suffix)}")
    print(f"TensorBoard: tensorboard --logdir {args.output / 'tensorboard'}")
    return 0


def _study_arguments(parser: argparse.ArgumentParser, scales: list[float],
                     output: str) -> None:  # fmt: skip
    """The arguments ``compare`` and ``robustness`` share."""
    from baselines.evaluation import OBJECTIVES

    parser.add_argument("env_id", choices=[*sorted(OBJECTIVES), "all"], help="the environment")
    parser.add_argument("--objective", choices=("time", "effort"), default=None,
                        help="one objective (default: every objective of the env)")
    parser.add_argument("--seeds", type=int, default=20,
                        help="perturbed starts per run (per training seed and controller)")
    parser.add_argument("--scales", type=float, nargs="*", default=scales,
                        help=f"start perturbation scales [rad, rad/s, m, m/s] (default "
                        f"{' '.join(map(str, scales))}; none: play no scale)")
    parser.add_argument("--trained", type=Path, default=None,
                        help="folder of the trained policies (default: baselines/trained; e.g. "
                        "the output of mdi-envs sweep)")
    parser.add_argument("--mpc", action="store_true",
                        help="also play the MPC rows around the reference: the shrinking-horizon "
                        "MPC (optimal.mpc; 0.1-1 s of compute per env step) and the tracking MPC "
                        "(optimal.tracking; milliseconds), time- and state-indexed; they need "
                        "CasADi")
    parser.add_argument("--controllers", nargs="+", default=None, metavar="LABEL",
                        help="play only these rows (labels as in the table, e.g. PPO HybridPPO "
                        "'MPC (shrinking horizon)') and merge them into the study already in "
                        "--output, keeping its other rows")
    parser.add_argument("--output", type=Path, default=Path(output),
                        help="folder for the JSON, PNG and Markdown results")
    parser.add_argument("--resume", action="store_true",
                        help="reuse the episodes already in OUTPUT/episodes.jsonl (every "
                        "finished episode is appended there): an interrupted run goes on")


def add_compare_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``compare`` subcommand to an argparse subparsers object; returns its parser."""
    parser = subparsers.add_parser(
        "compare",
        help="trained RL policies (every seed) vs the optimal reference: IQM and CIs of success, "
        "time and effort ratios",
        description="Play every trained policy of ENV_ID (--trained, default baselines/trained: "
        "one STEM.json + STEM.zip per training seed) and the untrained controllers (the optimal "
        "reference, open loop) from the nominal start and from --seeds perturbed starts at each "
        "--scales; print per algorithm the IQM and 95 % stratified-bootstrap CI over its seeds "
        "(rliable) of the success rate and of the time/effort ratios to the optimum as a "
        "Markdown table; write compare_ENV_OBJECTIVE.json, .md and .png (trajectories, brake "
        "schedules / slip modes, scores), seeds_ENV_OBJECTIVE.png (performance profiles, training "
        "curves), brake_ENV_OBJECTIVE.png (brake use per run, manipulator) and compare.md into "
        "--output (figures of a scale other than 0.01 end in _scaleS). ENV_ID 'all' runs both "
        "mission envs, every objective.",
    )
    _study_arguments(parser, [DEFAULT_SCALE], "results/compare")
    parser.add_argument("--bootstrap-reps", type=int, default=None,
                        help="bootstrap replications per CI (default 2000)")
    parser.set_defaults(handler=run_compare)
    return parser


ROBUSTNESS = ("Play every controller (the optimal reference open loop, --mpc, every trained "
              "seed) from --seeds perturbed starts at each of --scales and, at the default "
              "scale, under each model mismatch in the env only (link masses +-10 %; robot "
              "mass +-10 %, friction +-20 %); write robustness_ENV_OBJECTIVE.json and .png and "
              "robustness.md (success, mean over runs, and the time or effort ratio over the "
              "successes) into --output.")
"""The description of ``robustness`` (also ``python -m baselines.robustness``)."""


def add_robustness_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``robustness`` subcommand to an argparse subparsers object; returns its parser."""
    parser = subparsers.add_parser(
        "robustness",
        help="every controller under larger start perturbations and model mismatches",
        description=ROBUSTNESS,
    )
    robustness_arguments(parser)
    parser.set_defaults(handler=run_robustness)
    return parser


def robustness_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of ``robustness`` (also ``python -m baselines.robustness``)."""
    from baselines.evaluation import SCALES

    _study_arguments(parser, list(SCALES), "results/robustness")
    parser.add_argument("--mismatch", action=argparse.BooleanOptionalAction, default=True,
                        help="also play the model mismatches (default: yes)")
    parser.add_argument("--mismatches", nargs="+", default=None, metavar="LABEL",
                        help="play only these model mismatches (labels as in the table)")


def _studies(args: argparse.Namespace, prefix: str, nominal: bool,
             conditions: Callable[[str], list[Condition]]) -> list[Study]:  # fmt: skip
    """Play each env x objective of ``args`` and write ``{prefix}_ENV_OBJECTIVE.json``; the studies.

    With ``--controllers`` the study merges into the one in the folder, whose trained rows stay
    while their algorithm has policies in ``--trained`` or a shipped folder (``TRAINED_DIR``,
    ``DISTILLED_DIR``). ``nominal`` (the comparison): also the nominal starts, and bootstrap
    intervals in the aggregates.
    """
    import sys

    from baselines.evaluation import (
        DISTILLED_DIR,
        REFERENCE_NAMES,
        TRAINED_DIR,
        aggregate,
        evaluate,
        merge,
        shipped_algorithms,
    )
    from baselines.records import read_study, write_study

    if args.seeds < 1:
        raise SystemExit(f"{prefix}: --seeds must be >= 1, got {args.seeds}")
    jobs = [key for key in REFERENCE_NAMES
            if args.env_id in ("all", key[0]) and args.objective in (None, key[1])]
    if not jobs:
        raise SystemExit(f"{prefix}: {args.env_id} has no objective {args.objective!r}")
    trained_dir = TRAINED_DIR if args.trained is None else args.trained
    args.output.mkdir(parents=True, exist_ok=True)
    studies = []
    for env_id, objective in jobs:
        extra = []
        if args.mpc:
            from baselines.model_based import EXPERTS, lqr_controller

            for factory in EXPERTS.values():  # the LQR is a registered row
                if factory is lqr_controller:
                    continue
                controller = factory(env_id, objective)
                if controller is None:
                    raise SystemExit(f"{prefix}: --mpc needs CasADi (pip install "
                                     "'mdi-envs[optimal]')")
                extra.append(controller)
        try:
            study = evaluate(env_id, objective, conditions(env_id), args.seeds,
                             trained_dir=trained_dir, extra_controllers=extra,
                             only=args.controllers, nominal=nominal,
                             log_path=args.output / "episodes.jsonl", resume=args.resume,
                             show_bar=sys.stderr.isatty())  # fmt: skip
        except ValueError as error:
            raise SystemExit(f"{prefix}: {error}") from error
        path = args.output / f"{prefix}_{study.name}.json"
        if args.controllers is not None and path.exists():
            shipped = set().union(*(shipped_algorithms(env_id, objective, folder)
                                    for folder in (trained_dir, TRAINED_DIR, DISTILLED_DIR)))
            study = merge(read_study(path), study, shipped)
        study = aggregate(study, args.bootstrap_reps if nominal else 0)
        studies.append(study)
        print(f"wrote {write_study(study, path)}", file=sys.stderr)
    return studies


def run_compare(args: argparse.Namespace) -> int:
    """Handler of ``compare``: plays each env x objective, writes the study, figures and tables."""
    from baselines.evaluation import TRAINED_DIR
    from baselines.plots import plot_brake_use, plot_comparison, plot_seeds
    from baselines.records import Condition, read_study
    from baselines.tables import brake_use_table, comparison_report

    studies = _studies(args, "compare", True, lambda _: [Condition(s) for s in args.scales])
    trained_dir = args.trained or TRAINED_DIR
    for study in studies:  # the figures of the scales played now
        for condition in map(Condition, args.scales):
            tail = "" if condition.scale == DEFAULT_SCALE else f"_scale{condition.scale:g}"
            plot_comparison(study, args.output / f"compare_{study.name}{tail}.png",
                            condition.label)  # fmt: skip
            plot_seeds(study, args.output / f"seeds_{study.name}{tail}.png", trained_dir,
                       condition.label, args.bootstrap_reps)  # fmt: skip
            if brake_use_table([study]):
                plot_brake_use(study, args.output / f"brake_{study.name}{tail}.png",
                               condition.label)  # fmt: skip
        (args.output / f"compare_{study.name}.md").write_text(
            comparison_report([study], args.bootstrap_reps))
    everything = [read_study(path) for path in sorted(args.output.glob("compare_*.json"))]
    text = comparison_report(everything, args.bootstrap_reps)
    (args.output / "compare.md").write_text(text)
    print(text)
    return 0


def run_robustness(args: argparse.Namespace) -> int:
    """Handler of ``robustness``: plays each env x objective, writes the study, figure and table."""
    from baselines.evaluation import MISMATCHES
    from baselines.plots import plot_robustness
    from baselines.records import Condition, read_study
    from baselines.tables import robustness_table

    def conditions(env_id: str) -> list[Condition]:
        labels = list(MISMATCHES[env_id]) if args.mismatches is None else args.mismatches
        return [Condition(scale) for scale in args.scales] + [
            Condition(DEFAULT_SCALE, label) for label in labels if args.mismatch]

    for study in _studies(args, "robustness", False, conditions):
        plot_robustness(study, args.output / f"robustness_{study.name}.png")
    studies = [read_study(path) for path in sorted(args.output.glob("robustness_*.json"))]
    table = robustness_table(studies)
    (args.output / "robustness.md").write_text(table + "\n")
    print(table)
    return 0


def add_sweep_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``sweep`` subcommand to an argparse subparsers object; returns its parser."""
    from baselines.hyperparameters import ALGORITHMS, DEFAULT_OBJECTIVES, canonical_algorithm

    parser = subparsers.add_parser(
        "sweep",
        help="train the seed x algorithm x objective grid through Ray Tune (resumable)",
        description="Run mdi-envs train for every (env, objective, algorithm) of the settings in "
        "baselines/hyperparams and every --seeds, one Ray Tune trial each, locally on this "
        "machine's cores or on an existing Ray cluster (--address). A run whose STEM.json is "
        "already in --output is never rerun: the same command resumes an interrupted sweep. "
        "The results are the files of mdi-envs train; mdi-envs compare all --trained OUTPUT "
        "aggregates them over seeds. Needs the ray extra (pip install 'mdi-envs[ray]').",
    )
    parser.add_argument("--algos", nargs="+", type=canonical_algorithm, choices=ALGORITHMS,
                        default=["PPO", "HybridPPO"], help="algorithms (default: PPO HybridPPO)")
    parser.add_argument("--env-ids", nargs="+", choices=sorted(DEFAULT_OBJECTIVES), default=None,
                        help="environments (default: both)")
    parser.add_argument("--objectives", nargs="+", choices=("time", "effort"), default=None,
                        help="objectives (default: every objective the settings have)")
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2, 3, 4],
                        help="training seeds (default: 0 1 2 3 4)")
    parser.add_argument("--output", type=Path, default=Path("results/sweep"),
                        help="the results folder (on a cluster: a path every node shares)")
    parser.add_argument("--address", default=None,
                        help="an existing Ray cluster, e.g. auto or ray://HOST:10001 "
                        "(default: a local Ray instance)")
    parser.add_argument("--num-cpus", type=int, default=None,
                        help="cores of the local Ray instance (default: all)")
    parser.add_argument("--cpus-per-trial", type=float, default=1.0,
                        help="cores reserved per trial (default 1: torch runs on one thread)")
    parser.add_argument("--timesteps", type=int, default=None,
                        help="environment steps per run (default: the settings')")
    parser.add_argument("--num-envs", type=int, default=None,
                        help="batched copies per run (default: the settings')")
    parser.add_argument("--eval-episodes", type=int, default=10,
                        help="deterministic evaluation episodes after each run")
    parser.add_argument("--dry-run", action="store_true",
                        help="list the runs to do and the finished ones, run nothing")
    parser.set_defaults(handler=run_sweep)
    return parser


def run_sweep(args: argparse.Namespace) -> int:
    """Handler of ``sweep``: runs the grid, prints each run's outcome; returns 1 on a failure."""
    from baselines.sweep import grid, is_finished, sweep

    trials = grid(args.algos, args.seeds, args.env_ids, args.objectives)
    if not trials:
        raise SystemExit("sweep: no settings match these --algos, --env-ids and --objectives")
    if args.dry_run:
        for trial in trials:
            state = "finished" if is_finished(trial, args.output) else "to run"
            print(f"{trial.stem}: {state}")
        return 0
    outcome = sweep(trials, args.output, address=args.address, num_cpus=args.num_cpus,
                    cpus_per_trial=args.cpus_per_trial, total_timesteps=args.timesteps,
                    num_envs=args.num_envs, eval_episodes=args.eval_episodes,
                    log=print)  # fmt: skip
    print(f"sweep: {len(outcome['finished'])} finished now, {len(outcome['skipped'])} already "
          f"done, {len(outcome['failed'])} failed; results in {args.output}")  # fmt: skip
    return 1 if outcome["failed"] else 0


def add_simulate_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``simulate`` subcommand to an argparse subparsers object; returns its parser."""
    parser = subparsers.add_parser(
        "simulate",
        help="play one episode of an environment (random, a saved policy, open-loop actions or "
        "an optimal reference) and optionally save a GIF/MP4",
        description="Run one episode of ENV_ID and print its length, return, success, elapsed "
        "time and effort. POLICY is 'random', a trained SB3 model (.zip, with --algo), a file "
        "of normalised actions (.npy or .csv, one row per step) or 'reference:NAME' (the "
        "open-loop controls of a shipped optimal reference, at its own time step).",
    )
    parser.add_argument("env_id", help="e.g. mdi_envs/BlockableManipulator-v0")
    parser.add_argument("--policy", default="random", help="see above (default: random)")
    parser.add_argument("--algo", default="PPO",
                        help="algorithm of a .zip policy (PPO, SAC, HybridPPO)")
    parser.add_argument("--seed", type=int, default=0, help="reset seed")
    parser.add_argument("--steps", type=int, default=None, help="stop after this many steps")
    parser.add_argument("--save", type=Path, default=None, help="write a .gif or .mp4")
    parser.add_argument("--human", action="store_true", help="show a window while playing")
    parser.add_argument("--env-arg", action="append", default=[], metavar="KEY=VALUE",
                        type=_env_argument,
                        help="environment argument, e.g. objective=effort (repeatable)")
    parser.set_defaults(handler=run_simulate)
    return parser


def run_simulate(args: argparse.Namespace) -> int:
    """Handler of ``simulate``: plays the episode, prints its outcome; returns 0."""
    from mdi_envs.rendering import save_animation
    from mdi_envs.rollout import load_actions, open_loop_policy, rollout

    env_kwargs = dict(args.env_arg)
    policy: Any = args.policy
    if policy.startswith("reference:"):
        from optimal import load_reference
        from optimal.replay import env_actions, env_options

        reference = load_reference(policy.partition(":")[2])
        env_kwargs = {**env_options(reference), **env_kwargs}
        policy = open_loop_policy(env_actions(reference))
    elif policy.endswith(".zip"):
        from baselines.train import load_trained

        model = load_trained(args.algo, policy)
        policy = lambda obs: model.predict(obs, deterministic=True)[0]  # noqa: E731
    elif policy != "random":
        policy = open_loop_policy(load_actions(Path(policy)))
    result = rollout(args.env_id, policy, seed=args.seed, max_steps=args.steps,
                     record=args.save is not None, render_mode="human" if args.human else None,
                     **env_kwargs)  # fmt: skip
    info = result.last_info
    end = "terminated" if result.terminated else "truncated" if result.truncated else "stopped"
    print(f"{args.env_id}: {result.num_steps} steps ({end}), return {result.total_reward:.4f}, "
          f"success {info.get('is_success')}, elapsed {info.get('elapsed_time', 0.0):.3f} s, "
          f"effort {info.get('effort', 0.0):.4g} N^2 m^2 s")  # fmt: skip
    if args.save is not None:
        path = save_animation(result.frames, args.save, fps=30)
        print(f"wrote {path}")
    return 0


def _env_argument(text: str) -> tuple[str, Any]:
    """KEY=VALUE with VALUE read as a Python literal when it is one (numbers, booleans)."""
    import ast

    key, separator, value = text.partition("=")
    if not separator or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    try:
        return key, ast.literal_eval(value)
    except (ValueError, SyntaxError):
        return key, value


def add_demo_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``demo`` subcommand to an argparse subparsers object; returns its parser."""
    parser = subparsers.add_parser(
        "demo",
        help="the environments, the optimal references replayed (GIFs) and the RL vs MPC vs "
        "optimal comparison with trained policies played live",
        description="Make every environment with gym.make and show its spaces; replay every "
        "shipped optimal reference open loop through its env (a GIF each); print the committed "
        "RL vs MPC vs optimal table and play the best-evaluated trained policy of each "
        "algorithm from the nominal start beside the reference (a GIF per env and objective). "
        "Needs the rl and render extras. About a minute on a warm kernel cache.",
    )
    parser.add_argument("--output", type=Path, default=Path("results/demo"),
                        help="folder for the GIFs")
    parser.set_defaults(handler=run_demo)
    return parser


def run_demo(args: argparse.Namespace) -> int:
    """Handler of ``demo``: runs ``baselines.demo.run_demo``, prints the written paths."""
    from baselines.demo import run_demo as demo

    for path in demo(args.output):
        print(f"wrote {path}")
    return 0


__all__ = [
    "add_compare_parser", "add_demo_parser", "add_robustness_parser", "add_simulate_parser",
    "add_sweep_parser", "add_train_parser", "robustness_arguments", "run_compare", "run_demo",
    "run_robustness", "run_simulate", "run_sweep", "run_train",
]
