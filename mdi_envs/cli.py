"""The ``mdi-envs`` command line: the core's subcommands and the plug-ins' ones.

The core (this package) has ``compile`` (every kernel into the disk cache) and ``solve`` (one
Siconos file). Every other subcommand is a plug-in: ``optimal``, ``baselines`` and
``benchmarks`` register theirs (``optimize``; ``simulate``, ``demo``, ``train``, ``sweep``,
``compare``; ``bench``), and the core never imports them.

Plug-in interface
-----------------
A package adds a subcommand with an entry point of the group ``mdi_envs.commands`` in its
distribution's metadata, e.g. in ``pyproject.toml``::

    [project.entry-points."mdi_envs.commands"]
    optimize = "optimal.cli:add_optimize_parser"

* The entry point's name is the subcommand's name.
* Its object is a function ``add_parser(subparsers) -> argparse.ArgumentParser`` that calls
  ``subparsers.add_parser(NAME, help=..., description=...)`` with that same NAME, adds the
  arguments and sets the handler: ``parser.set_defaults(handler=run)``, where
  ``run(args: argparse.Namespace) -> int`` returns the exit code.
* The module holding the function (the package's ``cli`` module) is imported only when its
  subcommand runs or its ``--help`` is asked: ``mdi-envs --help`` lists the plug-ins by
  entry-point name, and neither it nor ``--version`` imports one. The module imports its heavy
  dependencies inside its handler, so that its own ``--help`` stays quick.
* Entry points are read from the installed metadata: after adding or renaming one, reinstall
  (``pip install --no-deps -e .``).
* A registered package need not be installed: ``benchmarks`` is not (see ``benchmarks/cli.py``)
  and runs from the repository's root as ``python -m mdi_envs bench``, which puts the current
  folder on the import path.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path
from typing import Any

import numpy as np

COMMAND_GROUP = "mdi_envs.commands"
"""The entry-point group of the plug-in subcommands."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``mdi-envs`` console script; returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    # The first non-option word names the subcommand (the top level has no option taking a
    # value): only that plug-in is loaded.
    command = next((word for word in argv if not word.startswith("-")), None)
    parser = _build_parser(command)
    args = parser.parse_args(argv)
    if not hasattr(args, "handler"):
        parser.print_help()
        return 0
    return int(args.handler(args))


def plugin_commands() -> dict[str, EntryPoint]:
    """The registered plug-in subcommands, name -> entry point (nothing imported)."""
    found: dict[str, EntryPoint] = {}
    for entry in entry_points(group=COMMAND_GROUP):
        if entry.name in found and found[entry.name].value != entry.value:
            raise RuntimeError(f"two {COMMAND_GROUP} entry points are named {entry.name!r}: "
                               f"{found[entry.name].value} and {entry.value}")
        found[entry.name] = entry
    return found


def _build_parser(command: str | None) -> argparse.ArgumentParser:
    """The parser of the core subcommands, and of the plug-in named ``command`` if one is."""
    from mdi_envs import __version__

    parser = argparse.ArgumentParser(
        prog="mdi-envs",
        description="Nonsmooth rigid-body mechanics (Moreau-Jean MDIs) for control and RL.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(title="commands")

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
    compile_.add_argument("--make-only", action="store_true",
                          help="only what gym.make needs (each id and its documented variants): "
                          "no vector env, no stepper; about 60 %% of the time on an empty cache")
    compile_.set_defaults(handler=_run_compile)

    for name, entry in plugin_commands().items():
        if name in commands.choices:
            raise RuntimeError(f"the {COMMAND_GROUP} entry point {entry.value} is named like "
                               f"the core subcommand {name!r}")
        if name == command:
            _add_plugin(commands, name, entry)
        else:  # listed by name only; its module is not imported
            commands.add_parser(name, help=f"see mdi-envs {name} --help ({entry.module})")
    return parser


def _add_plugin(commands: Any, name: str, entry: EntryPoint) -> None:
    """Import the plug-in of subcommand ``name`` and let it add its parser."""
    try:
        add_parser = entry.load()
    except ImportError as error:
        raise SystemExit(f"mdi-envs {name}: its plug-in {entry.value} cannot be imported "
                         f"({error}); a plug-in package that is not installed runs from the "
                         f"folder that holds it: python -m mdi_envs {name}") from error
    add_parser(commands)
    if name not in commands.choices:
        raise RuntimeError(f"the {COMMAND_GROUP} entry point {name} = {entry.value} did not add "
                           f"a subcommand named {name!r}")


def _run_compile(args: argparse.Namespace) -> int:
    from mdi_envs import ENV_IDS
    from mdi_envs._kernel_cache import digest_dir
    from mdi_envs.precompile import MAKE_STAGES, STAGES, compile_envs

    env_ids = list(ENV_IDS) if "all" in args.env_ids else args.env_ids
    started = time.perf_counter()
    try:
        seconds = compile_envs(env_ids, jobs=args.jobs,
                               stages=MAKE_STAGES if args.make_only else STAGES)
    except (ValueError, RuntimeError) as error:
        print(f"mdi-envs compile: {error}", file=sys.stderr)
        return 2
    for env_id, took in seconds.items():
        print(f"{env_id}: {took:.1f} s")
    print(f"compiled {len(seconds)} env ids in {time.perf_counter() - started:.1f} s "
          f"(cache: {digest_dir()})")
    return 0


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
