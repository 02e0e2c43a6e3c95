"""``mdi-envs bench [NAME ...] [--quick] [--skip NAME ...]``: the benchmark suite, one command.

Each NAME runs one module's ``main`` into ``--output``; the headline table then holds the targets of
the results found there. Exit code 1 when a benchmark crashes or a stress case fails.
Registered as the ``mdi_envs.commands`` entry point ``bench``; not installed with the package, it
runs from the repository's root (``python -m mdi_envs bench``), whose results folder it writes.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
import traceback
from pathlib import Path
from typing import Any

BENCHMARKS = {  # NAME: (module with ``main(argv)``, what it measures)
    "solvers": ("benchmarks.solvers", "LCP methods: work vs size, Lemke vs QuantEcon"),
    "engine": ("benchmarks.engine", "µs per step (single, batched) vs MuJoCo, the shortcuts, "
               "the brake stop"),
    "envs": ("benchmarks.envs", "env.step and vector-env throughput vs Acrobot-v1 and MuJoCo"),
    "precision": ("benchmarks.work_precision", "error vs wall time per scene vs closed forms, "
                  "the event-driven reference and MuJoCo"),
    "fc3d": ("benchmarks.fc3d", "every FC3D method on the Siconos fc3d peer problems"),
    "stress": ("benchmarks.stress", "the stress cases of tests/stress with their criteria"),
    "startup": ("benchmarks.startup", "interpreter start to the first env step, warm and cold"),
    "control": ("benchmarks.control", "model-based controllers: compute per step over the control "
                "period, success and cost from perturbed starts"),
}
DEFAULT_OUTPUT = Path("benchmarks/results")
"""Where the full run writes (committed); ``--quick`` writes into its ``quick/`` subfolder."""


def add_bench_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``bench`` subcommand to an argparse subparsers object; returns its parser."""
    listing = "; ".join(f"{name}: {text}" for name, (_, text) in BENCHMARKS.items())
    parser = subparsers.add_parser(
        "bench",
        help="run the benchmark suite (or some of it) and write JSON + PNG results",
        description=f"Benchmarks: {listing}. Writes into --output (default "
        f"{DEFAULT_OUTPUT}, --quick: {DEFAULT_OUTPUT / 'quick'}) and a headline table of all "
        "results found there. Needs the bench extra (pip install 'mdi-envs[bench]').",
    )
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help=f"benchmarks to run (default: all of {', '.join(BENCHMARKS)})")
    parser.add_argument("--quick", action="store_true",
                        help="small grids and budgets (about 1-2 min for all; used by make test)")
    parser.add_argument("--skip", nargs="+", default=[], metavar="NAME",
                        help="benchmarks to leave out (make test: stress, which pytest runs)")
    parser.add_argument("--output", type=Path, default=None, help="results folder")
    parser.set_defaults(handler=run_bench)
    return parser


def run_bench(args: argparse.Namespace) -> int:
    """Handler of ``bench``: runs the chosen benchmarks, then the headline table; exit code."""
    from benchmarks.report import write_headline

    names = [name for name in args.names or BENCHMARKS if name not in args.skip]
    unknown = [name for name in [*names, *args.skip] if name not in BENCHMARKS]
    if unknown:
        raise SystemExit(f"bench: unknown benchmark {', '.join(unknown)}; "
                         f"choose from {', '.join(BENCHMARKS)}")  # fmt: skip
    output = args.output or (DEFAULT_OUTPUT / "quick" if args.quick else DEFAULT_OUTPUT)
    output.mkdir(parents=True, exist_ok=True)
    failures: list[str] = []
    argv = ["--output", str(output)] + (["--quick"] if args.quick else [])
    for name in names:
        module_name, start = BENCHMARKS[name][0], time.perf_counter()
        print(f"== bench {name} ({module_name}){' --quick' if args.quick else ''}", flush=True)
        try:
            code = importlib.import_module(module_name).main(argv)
        except Exception:  # a crash of one benchmark is reported, the others still run
            traceback.print_exc()
            code = 1
        failures += [name] if code else []
        print(f"== bench {name}: {'FAILED' if code else 'ok'} in "
              f"{time.perf_counter() - start:.0f} s", flush=True)  # fmt: skip
    print(write_headline(output))
    if failures:
        print(f"bench: failed: {', '.join(failures)}", file=sys.stderr)
        return 1
    return 0
