"""``mdi-envs optimize NAME``: recompute one reference with progress output.

Registered in ``pyproject.toml`` as the ``mdi_envs.commands`` entry point ``optimize`` (the
plug-in interface is in ``mdi_envs/cli.py``); the parser's handler is ``run_optimize``.
Example: ``mdi-envs optimize manipulator_time --output results/optimal`` (about a minute)
prints one line per continuation stage and per replay, writes ``NAME.npz``/``NAME.json`` and
the PNG figures into ``--output`` and, with ``--install``, into the package's references.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def add_optimize_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``optimize`` subcommand to an argparse subparsers object; returns its parser."""
    from optimal.problems import PROBLEMS

    parser = subparsers.add_parser(
        "optimize",
        help="compute an optimal-control reference (penalty/continuation, CasADi + IPOPT)",
        description="Solve one named problem from its naive guess by the combined penalty/"
        "continuation method, replay its controls in the simulator at h and h/10, and save "
        "arrays, metadata and figures. Needs CasADi (pip install 'mdi-envs[optimal]').",
    )
    parser.add_argument("name", choices=sorted(PROBLEMS), help="the problem")
    parser.add_argument("--output", type=Path, default=Path("results/optimal"),
                        help="folder for NAME.npz, NAME.json and the PNGs")
    parser.add_argument("--intervals", type=int, default=None, help="N (default: the problem's)")
    parser.add_argument("--workers", type=int, default=None,
                        help="processes for a multi-start's starts (default: one per core)")
    parser.add_argument("--starts", type=int, default=None,
                        help="run the global search with this many starts (naive guess, the "
                        "paper's schedule where it applies, random ones), each continued and "
                        "mode-neighbourhood searched, then refine the best (default: the "
                        "plain continuation from the naive guess)")
    parser.add_argument("--refine", type=_factors, default=(2, 4),
                        help="with --starts: refinement factors, comma-separated (default 2,4; "
                        "'' for none)")
    parser.add_argument("--seed", type=int, default=0, help="with --starts: of the random starts")
    parser.add_argument("--install", action="store_true",
                        help="also write the reference into optimal/references (package data), "
                        "if it converged and its replay reaches the goal")
    parser.set_defaults(handler=run_optimize)
    return parser


def run_optimize(args: argparse.Namespace) -> int:
    """Handler of ``optimize``: returns 0 when the reference converged and reaches the goal."""
    from optimal.plots import plot_reference, plot_search
    from optimal.references import REFERENCE_DIR, save_reference
    from optimal.solve import search_reference, solve_problem

    def progress(line: str) -> None:
        print(line, flush=True)

    pngs = []
    if args.starts is None:
        reference = solve_problem(args.name, args.intervals, workers=args.workers,
                                  progress=progress)
    else:
        reference, report = search_reference(args.name, args.starts, args.refine,
                                             args.intervals, seed=args.seed,
                                             workers=args.workers, progress=progress)
        search_path = args.output / f"{args.name}_search.json"
        search_path.parent.mkdir(parents=True, exist_ok=True)
        search_path.write_text(json.dumps(report, indent=1))
        print(f"saved {search_path}")
        pngs.append(plot_search(reference, args.output))
    meta = reference.metadata
    path = save_reference(reference, args.output)
    print(f"{args.name}: t_f = {meta['final_time']:.4f} s, cost = {meta['cost']:.6g}, "
          f"N = {meta['num_intervals']}, {meta['total_time']:.1f} s wall, "
          f"converged: {meta['converged']}")
    print(f"saved {path} and {path.with_suffix('.npz')}")
    for png in [*pngs, *plot_reference(reference, args.output)]:
        print(f"saved {png}")
    ok = meta["converged"] and meta["replay"][0]["reaches_goal"]
    if args.install and ok:
        print(f"installed {save_reference(reference, REFERENCE_DIR)}")
    elif args.install:
        print("not installed: the continuation did not converge or the replay misses the goal")
    return 0 if ok else 1


def _factors(text: str) -> tuple[int, ...]:
    """"2,4" -> (2, 4); "" -> ()."""
    try:
        factors = tuple(int(part) for part in text.split(",") if part.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated integers, got {text!r}") from None
    if any(b <= a for a, b in zip((1, *factors), factors, strict=False)):
        raise argparse.ArgumentTypeError(f"factors must increase from 2, got {text!r}")
    return factors


__all__ = ["add_optimize_parser", "run_optimize"]
