"""FC3D on every Siconos peer problem: time and residual of each method, to tolerance 1e-8.

``python -m benchmarks.fc3d [--output DIR] [--quick]`` (quick: n <= 150) writes ``fc3d.json`` and
``fc3d.png``; a problem is solved when some method converges (residual recomputed).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks import report
from benchmarks.problems import peer_data_dir
from benchmarks.report import plt
from benchmarks.timing import TimingPlan, arguments, time_interleaved
from mdi_envs.solvers import SolverStatus, fc3d_residual, solve_fc3d
from mdi_envs.solvers.siconos_io import read_friction_contact

TOL = 1e-8
METHODS: dict[str, dict[str, Any]] = {
    "newton_ac": {"max_iter": 100},
    "nsgs": {"max_iter": 2000},
    "hybrid": {"max_iter": 500},
    "fixed_point_socp": {"max_iter": 300},
}
"""Method -> options of the run (budgets: Newton steps or sweeps)."""

QUICK_MAX_N = 150
PLAN = TimingPlan(budget_s=0.1, min_rounds=1, max_rounds=50, min_batch_s=0.0)
"""Each solve: one untimed call, then single calls for about 0.1 s (at most 50); the median."""


def run(output: Path, quick: bool) -> str:
    """Run every method on every peer problem, write the JSON and the plot, return the table."""
    settings = {"quick": quick, "tol": TOL, "methods": METHODS}
    with report.study("fc3d", output, settings) as (record, log, _):
        folder = peer_data_dir() / "fc3d"
        files = sorted(folder.glob("*.dat")) if folder.is_dir() else []
        if not files:
            log(f"peer data {folder} absent: nothing to run")
        for method in METHODS:  # compile (or load) every method's kernels outside the timings
            solve_fc3d(np.eye(6) + 0.1, np.array([-1.0, 0.5, 0.0, -1.0, 0.0, 2.0]),
                       np.array([0.3, 0.3]), method=method)
        rows = []
        for path in files:
            data = read_friction_contact(path)
            n = int(data.q.shape[0])
            if quick and n > QUICK_MAX_N:
                continue
            row: dict[str, Any] = {"name": path.stem, "n": n, "contacts": n // 3}
            for method, options in METHODS.items():
                timed = time_interleaved({method: partial(
                    solve_fc3d, data.W, data.q, data.mu, method=method, tol=TOL, **options)}, PLAN)
                result, seconds = timed[method].result, timed[method].median_s
                row[method] = {"time_s": seconds, "status": result.status.name,
                               "residual": float(fc3d_residual(data.W, data.q, data.mu, result.r)),
                               "iterations": int(result.num_iter),
                               "converged": result.status is SolverStatus.CONVERGED}
            row["solved"] = any(row[m]["converged"] for m in METHODS)
            rows.append(row)
            log(f"{path.stem} (n={n}): " + ", ".join(f"{m} {row[m]['status']}" for m in METHODS))
        record.update({"problems": rows, "solved_by_any": sum(r["solved"] for r in rows),
                       "solved_by_method": {m: sum(r[m]["converged"] for r in rows)
                                            for m in METHODS}})
        if rows:  # without peer data nothing is drawn (a log axis of no values fails)
            plot(rows, output / "fc3d.png")
    return report.summary(record, ("numpy", "numba", "scipy"))


def plot(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """Two panels per problem: time per method (log) and residual per method (log)."""
    names = [f"{r['name']} (n={r['n']})" for r in rows]
    y = np.arange(len(rows))
    fig, (ax_t, ax_r) = plt.subplots(1, 2, figsize=(13, 0.25 * len(rows) + 2), sharey=True)
    width = 0.8 / len(METHODS)
    for k, method in enumerate(METHODS):
        offset = (k - (len(METHODS) - 1) / 2) * width
        times = [r[method]["time_s"] for r in rows]
        residuals = [max(r[method]["residual"], 1e-18) for r in rows]
        colors = [f"C{k}" if r[method]["converged"] else "lightgrey" for r in rows]
        ax_t.barh(y + offset, times, width, color=colors, edgecolor=f"C{k}", label=method)
        ax_r.barh(y + offset, residuals, width, color=colors, edgecolor=f"C{k}", label=method)
    ax_r.axvline(TOL, color="k", lw=0.8, ls=":")
    for ax, label in ((ax_t, "time per solve (s)"), (ax_r, "residual (0 drawn at 1e-18)")):
        ax.set_xscale("log")
        ax.set_xlabel(label)
        ax.grid(True, axis="x", which="both", alpha=0.3)
    ax_t.set_yticks(y, names, fontsize=7)
    ax_t.invert_yaxis()
    ax_t.legend(fontsize=8, title="grey fill: not converged", title_fontsize=7)
    fig.suptitle(f"FC3D on the Siconos peer problems, tol {TOL:g}, from r = 0")
    report.save_figure(fig, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> None:
    """Command-line entry point."""
    args = arguments(__doc__, argv)
    print(run(args.output, args.quick))


if __name__ == "__main__":
    main()
