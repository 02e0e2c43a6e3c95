"""The ``mdi-envs`` command line: one tool for the project's main jobs.

Subcommands: ``demo`` (solvers and the manipulator), ``compile`` (every kernel into the disk
cache), ``solve`` (one Siconos file),
``simulate`` (one episode of an environment, optionally saved as GIF/MP4), ``optimize``
(an optimal-control reference), ``train`` (an SB3 baseline), ``sweep`` (the seed x algorithm x
task grid of ``train`` through Ray Tune), ``compare`` (the trained baselines, over seeds,
against the optimal references) and ``bench`` (the benchmark suite).
Each subcommand imports what it needs inside its handler.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``mdi-envs`` console script; returns the exit code."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "handler"):
        parser.print_help()
        return 0
    return int(args.handler(args))


def _build_parser() -> argparse.ArgumentParser:
    from mdi_envs import __version__

    parser = argparse.ArgumentParser(
        prog="mdi-envs",
        description="Nonsmooth rigid-body mechanics (Moreau-Jean MDIs) for control and RL.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(title="commands")

    demo = commands.add_parser(
        "demo",
        help="demonstration: every LCP method on growing problems, and the manipulator "
        "under the paper's brake schedule, with plots",
        description="Solve random contact-like LCPs (n = 2..100) with every registered method "
        "and print a table of status, iterations, residual and time; then run the blockable "
        "manipulator under the paper's brake schedule by time-stepping and by the event-driven "
        "reference; then replay every shipped optimal reference open loop through its "
        "Gymnasium env. Saves PNG plots and GIFs. Takes about 1-2 min (mostly numba "
        "compilation).",
    )
    demo.add_argument("--output", type=Path, default=Path("results/demo"), help="PNG folder")
    demo.add_argument("--seed", type=int, default=0, help="random seed of the problems")
    demo.set_defaults(handler=_run_demo)

    solve = commands.add_parser(
        "solve",
        help="solve one Siconos-format LCP or friction-contact file and report the result",
        description="Read an LCP (n, matrix block, q) or, with --problem friction, a local "
        "friction-contact problem (dimension 2 or 3, W, q, mu) in Siconos' text format and "
        "solve it (solve_lcp, solve_fc2d or solve_fc3d).",
    )
    solve.add_argument("path", type=Path, help="the .dat file")
    solve.add_argument("--problem", choices=("lcp", "friction"), default="lcp",
                       help="the file's problem type (default: lcp)")
    solve.add_argument("--method", default=None,
                       help="method (default: lemke for an LCP, newton_ac for friction)")
    solve.set_defaults(handler=_run_solve)

    simulate = commands.add_parser(
        "simulate",
        help="play one episode of an environment (random, a saved policy, open-loop actions or "
        "an optimal reference) and optionally save a GIF/MP4",
        description="Run one episode of ENV_ID and print its length, return, success, elapsed "
        "time and effort. POLICY is 'random', a trained SB3 model (.zip, with --algo), a file "
        "of normalised actions (.npy or .csv, one row per step) or 'reference:NAME' (the "
        "open-loop controls of a shipped optimal reference, at its own time step).",
    )
    simulate.add_argument("env_id", help="e.g. mdi_envs/BlockableManipulator-v0")
    simulate.add_argument("--policy", default="random", help="see above (default: random)")
    simulate.add_argument("--algo", default="PPO",
                          help="algorithm of a .zip policy (PPO, SAC, HybridPPO)")
    simulate.add_argument("--seed", type=int, default=0, help="reset seed")
    simulate.add_argument("--steps", type=int, default=None, help="stop after this many steps")
    simulate.add_argument("--save", type=Path, default=None, help="write a .gif or .mp4")
    simulate.add_argument("--human", action="store_true", help="show a window while playing")
    simulate.add_argument("--env-arg", action="append", default=[], metavar="KEY=VALUE",
                          help="environment argument, e.g. objective=effort (repeatable)")
    simulate.set_defaults(handler=_run_simulate)

    compile_ = commands.add_parser(
        "compile",
        help="compile every kernel of the environments into the disk cache, so that later "
        "processes start in about a second",
        description="Compile (or load) every kernel an environment id uses: gym.make and "
        "gym.make_vec with each documented variant, and the model's stepper; one worker "
        "process per id, all cores. The kernels are cached on disk (MDI_ENVS_CACHE_DIR, "
        "default ~/.cache/mdi_envs) and shared by every later process. Takes a few minutes "
        "on an empty cache (every kernel compiled), seconds on a warm one.",
    )
    compile_.add_argument("env_ids", nargs="*", default=["all"], metavar="ENV_ID",
                          help="ids to compile, or 'all' (default)")
    compile_.add_argument("--jobs", type=int, default=None,
                          help="worker processes (default: one per core)")
    compile_.set_defaults(handler=_run_compile)

    from baselines.cli import add_compare_parser, add_sweep_parser, add_train_parser
    from benchmarks.cli import add_bench_parser
    from optimal.cli import add_optimize_parser

    add_optimize_parser(commands)
    add_train_parser(commands)
    add_sweep_parser(commands)
    add_compare_parser(commands)
    add_bench_parser(commands)
    return parser


def _env_argument(text: str) -> tuple[str, Any]:
    """KEY=VALUE with VALUE read as a Python literal when it is one (numbers, booleans)."""
    import ast

    key, separator, value = text.partition("=")
    if not separator or not key:
        raise SystemExit(f"--env-arg expects KEY=VALUE, got {text!r}")
    try:
        return key, ast.literal_eval(value)
    except (ValueError, SyntaxError):
        return key, value


def _run_compile(args: argparse.Namespace) -> int:
    from mdi_envs import ENV_IDS
    from mdi_envs._kernel_cache import digest_dir
    from mdi_envs.precompile import compile_envs

    env_ids = list(ENV_IDS) if "all" in args.env_ids else args.env_ids
    started = time.perf_counter()
    try:
        seconds = compile_envs(env_ids, jobs=args.jobs)
    except (ValueError, RuntimeError) as error:
        print(f"mdi-envs compile: {error}", file=sys.stderr)
        return 2
    for env_id, took in seconds.items():
        print(f"{env_id}: {took:.1f} s")
    print(f"compiled {len(seconds)} env ids in {time.perf_counter() - started:.1f} s "
          f"(cache: {digest_dir()})")
    return 0


def _run_simulate(args: argparse.Namespace) -> int:
    from mdi_envs.rendering import save_animation
    from mdi_envs.rollout import load_actions, open_loop_policy, rollout

    env_kwargs = dict(_env_argument(text) for text in args.env_arg)
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


def _contact_like_lcp(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A Delassus-like LCP: M = J J^T / n + 0.01 I (symmetric PD), q with both signs."""
    J = rng.standard_normal((n, n + 3))
    return J @ J.T / n + 0.01 * np.eye(n), rng.standard_normal(n)


def _run_demo(args: argparse.Namespace) -> int:
    from mdi_envs.plotting import plot_complementarity, plot_time_vs_size
    from mdi_envs.solvers import LCP_METHODS, solve_lcp

    rng = np.random.default_rng(args.seed)
    args.output.mkdir(parents=True, exist_ok=True)
    sizes = [2, 3, 5, 10, 20, 50, 100]
    methods = LCP_METHODS.names()
    timings: dict[str, tuple[list[int], list[float]]] = {name: ([], []) for name in methods}
    print(f"{'n':>4} {'method':<12} {'status':<16} {'iter':>6} {'residual':>10} {'time':>10}")
    for n in sizes:
        M, q = _contact_like_lcp(n, rng)
        for name in methods:
            if name == "enumerative" and n > 10:
                continue
            options: dict[str, Any] = {"max_iter": 100_000} if name == "pgs" else {}
            solve_lcp(M, q, method=name, **options)  # compile and warm up
            elapsed = np.inf
            for _ in range(5):  # best of five: the least disturbed by other processes
                start = time.perf_counter()
                result = solve_lcp(M, q, method=name, **options)
                elapsed = min(elapsed, time.perf_counter() - start)
            timings[name][0].append(n)
            timings[name][1].append(elapsed)
            print(
                f"{n:>4} {name:<12} {result.status.name:<16} {result.num_iter:>6} "
                f"{result.residual:>10.2e} {elapsed * 1e6:>8.1f}us"
            )
    M, q = _contact_like_lcp(40, rng)
    result = solve_lcp(M, q)
    written = [
        plot_time_vs_size(
            timings, "LCP methods on contact-like problems", args.output / "lcp_methods_time.png"
        ),
        plot_complementarity(
            result.z, result.w, f"Lemke on n = 40: residual {result.residual:.1e}",
            args.output / "lcp_complementarity.png",
        ),
    ]
    written.append(_manipulator_demo(args.output))
    written += _reference_replays(args.output)
    for path in written:
        print(f"wrote {path}")
    return 0


def _reference_replays(output: Path) -> list[Path]:
    """Replay each shipped optimal reference open loop through its gym env, saving a GIF."""
    from mdi_envs.rendering import save_animation
    from mdi_envs.rollout import open_loop_policy, rollout
    from optimal import available_references, load_reference
    from optimal.replay import env_actions, env_options

    written = []
    for name in available_references():
        reference = load_reference(name)
        result = rollout(reference.metadata["env_id"], open_loop_policy(env_actions(reference)),
                         record=True, **env_options(reference))  # fmt: skip
        info = result.last_info
        print(f"optimal reference {name} replayed in {reference.metadata['env_id']}: "
              f"{result.num_steps} steps, elapsed {info['elapsed_time']:.3f} s, "
              f"success {info['is_success']}, effort {info['effort']:.4g} N^2 m^2 s")
        written.append(save_animation(result.frames[::2], output / f"{name}.gif", fps=15))
    return written


def _manipulator_demo(output: Path) -> Path:
    """The paper's brake schedule on the manipulator: time-stepping against event-driven."""
    from mdi_envs.mechanics import BlockableManipulator
    from mdi_envs.plotting import plot_manipulator_rollout
    from mdi_envs.stepping import (
        MoreauJeanStepper,
        bang_bang,
        brake_schedule,
        simulate_manipulator,
    )

    horizon, dt = 4.53, 1e-3  # [s]
    torque = bang_bang(1.0, [2.264])  # [N m], reversed at half the horizon
    brake = brake_schedule([0.0, 1.07, 2.39], [0.41, 1.84])  # the paper's schedule [s]
    print("\nBlockable manipulator, the paper's brake schedule (engaged at 0, 1.07, 2.39 s; "
          "released at 0.41, 1.84 s), bang-bang torque 1 N m, dt = 1 ms:")
    stepper = MoreauJeanStepper(BlockableManipulator, time_step=dt)
    num_steps = round(horizon / dt)
    t = np.asarray(dt * np.arange(1, num_steps + 1), dtype=np.float64)
    q, u = np.zeros((num_steps, 2)), np.zeros((num_steps, 2))
    impulse = np.zeros(num_steps)
    state_q, state_u = np.zeros(2), np.zeros(2)
    start = time.perf_counter()
    for k in range(num_steps):
        middle = (k + 0.5) * dt
        result = stepper.step(state_q, state_u, torque(middle), brake(middle))
        state_q, state_u = result.q, result.u
        q[k], u[k], impulse[k] = state_q, state_u, result.impulses[0]
    elapsed = time.perf_counter() - start
    reference = simulate_manipulator(None, [0.0, 0.0], [0.0, 0.0], torque, brake, horizon,
                                     sample_times=t)
    q_ref, u_ref = reference.evaluate(t)
    error = max(np.abs(q - q_ref).max(), np.abs(u - u_ref).max())
    print(f"  {num_steps} steps in {elapsed:.2f} s (first call compiles); final "
          f"(alpha, beta) = ({q[-1, 0]:.4f}, {q[-1, 1]:.4f}) rad; max deviation from the "
          f"event-driven reference {error:.2e}")
    return plot_manipulator_rollout(
        t, q, u, impulse, (t, q_ref, u_ref),
        "Blockable manipulator: Moreau-Jean (dt = 1 ms) vs event-driven reference",
        output / "manipulator_brake_schedule.png",
    )


def _run_solve(args: argparse.Namespace) -> int:
    from mdi_envs.solvers import solve_fc2d, solve_fc3d, solve_lcp
    from mdi_envs.solvers.siconos_io import read_friction_contact, read_lcp

    if args.problem == "friction":
        data = read_friction_contact(args.path, sparse=True)
        method = args.method or "newton_ac"
        start = time.perf_counter()
        contact: Any = (solve_fc2d(data.W, data.q, data.mu, method=method)
                        if data.dimension == 2 else
                        solve_fc3d(np.asarray(data.W.todense()),  # type: ignore[union-attr]
                                   data.q, data.mu, method=method))
        elapsed = time.perf_counter() - start
        print(f"{args.path.name}: {data.mu.shape[0]} contacts of dimension {data.dimension}, "
              f"method {contact.method}")
        print(f"status {contact.status.name}, {contact.num_iter} iterations, residual "
              f"{contact.residual:.3e}, {elapsed * 1e3:.2f} ms (including compilation on "
              "first use)")
        return 0 if contact.status.name == "CONVERGED" else 1
    M, q = read_lcp(args.path)
    start = time.perf_counter()
    result = solve_lcp(M, q, method=args.method or "lemke")
    elapsed = time.perf_counter() - start
    print(f"{args.path.name}: n = {q.shape[0]}, method {result.method}")
    print(f"status {result.status.name}, {result.num_iter} iterations, residual "
          f"{result.residual:.3e}, {elapsed * 1e3:.2f} ms (including compilation on first use)")
    if q.shape[0] <= 12:
        print("z =", np.array2string(result.z, precision=6))
    return 0 if result.status.is_success else 1


if __name__ == "__main__":
    sys.exit(main())
