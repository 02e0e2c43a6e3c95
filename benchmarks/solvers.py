"""LCP solver benchmark: work vs size for every method, and our Lemke against QuantEcon's.

``python -m benchmarks.solvers [--output DIR] [--quick]`` writes ``solvers.json``,
``solvers_{time,residual}_vs_size.png`` and ``lemke_vs_quantecon.png``. Lemke is timed through
the driver ``solve_lcp`` and its compiled entry ``lemke_solve``, interleaved with QuantEcon's.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from benchmarks import problems as E
from benchmarks import report, timing
from benchmarks.report import bars, log_lines, plt, save_figure, summary
from benchmarks.timing import Log, TimingPlan

ENTRY_KEYS = ("driver", "kernel", "quantecon")  # the entries of the QuantEcon comparison
RESIDUAL_FLOOR = 1e-18  # zero residuals are drawn here on log axes
ENTRY_TITLES = {"quantecon": "QuantEcon lcp_lemke"}


@dataclass(frozen=True)
class BenchConfig:
    """Sizes n and instances of the size study and the QuantEcon comparison, their timing."""

    sizes: tuple[int, ...]
    instances: int
    size_plan: TimingPlan
    peer_sizes: tuple[int, ...]
    peer_instances: int
    peer_plan: TimingPlan
    cold_compile: bool


FULL = BenchConfig(
    sizes=(2, 3, 5, 10, 20, 50, 100, 200), instances=5,
    size_plan=TimingPlan(budget_s=0.05, min_rounds=5, max_rounds=100),
    peer_sizes=tuple(range(10, 101, 10)), peer_instances=2,
    peer_plan=TimingPlan(budget_s=0.25, min_rounds=9, max_rounds=400), cold_compile=True)
QUICK = BenchConfig(
    sizes=(2, 5, 10, 50), instances=2,
    size_plan=TimingPlan(budget_s=0.005, min_rounds=3, max_rounds=20),
    peer_sizes=(10, 50, 100), peer_instances=1,
    peer_plan=TimingPlan(budget_s=0.02, min_rounds=3, max_rounds=30), cold_compile=False)


def measure_first_calls(config: BenchConfig, log: Log) -> dict[str, Any]:
    """First-call (compile or cache-load) times, each from a fresh interpreter (``probes``)."""
    results = {}
    for label, cold in (("warm_cache", False), ("cold_cache", True))[:1 + config.cold_compile]:
        log(f"first-call probe ({label}) in a fresh interpreter ...")
        with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache_dir:
            cache = cache_dir if cold else None  # numba's cache, and the package's own
            process = timing.fresh_python("-m", "benchmarks.probes", "first-call",
                                          NUMBA_CACHE_DIR=cache, MDI_ENVS_CACHE_DIR=cache)
        results[label] = (json.loads(process.stdout) if process.returncode == 0
                          else {"error": process.stderr.strip().splitlines()[-1:]})
        calls = results[label].get("first_call_s", {})
        log("  " + ", ".join(f"{k} {v * 1e3:.0f} ms" for k, v in calls.items()))
    return results


def time_problem(problem: E.Problem, chosen: Sequence[E.Entry], plan: TimingPlan) -> dict[str, Any]:
    """Time entries on one problem in interleaved rounds and read their outcomes."""
    calls = {e.name: (lambda e=e: e.solve(problem.M, problem.q)) for e in chosen}
    timed = timing.time_interleaved(calls, plan)
    return {e.name: {"time": timed[e.name].summary(),
                     "outcome": asdict(e.read(timed[e.name].result, problem.M, problem.q))}
            for e in chosen}


def size_study(config: BenchConfig, log: Log) -> list[dict[str, Any]]:
    """Every method on every (family, n, instance) of the grid; one record per entry."""
    records = []
    for family in E.FAMILIES:
        for n in config.sizes:  # the methods applicable at n, and QuantEcon's Lemke
            entries = [E.driver_entry(m) for m in E.LCP_METHODS
                       if m != "enumerative" or n <= E.ENUMERATIVE_MAX_N] + [E.QUANTECON]
            latest = [{"family": family, "n": n, "instance": i, "entry": name, **measured}
                      for i in range(config.instances) for name, measured in time_problem(
                          E.random_problem(family, n, i), entries, config.size_plan).items()]
            records += latest
            log(f"size study {family} n={n}: " + ", ".join(
                f"{r['entry']} {r['time_median_s'] * 1e6:.3g} µs"
                for r in aggregate_size_study(latest)))
    return records


def comparison_problems(config: BenchConfig, log: Log) -> list[E.Problem]:
    """The Siconos peer LCP files (if present) and the random problems n = 10, 20, ..., 100."""
    peers = E.peer_lcp_problems()
    log(f"peer data: {len(peers)} LCP files from {E.peer_data_dir() / 'lcp'}" if peers else
        f"peer data: {E.peer_data_dir() / 'lcp'} absent; skipping the Siconos files (set "
        "MDI_ENVS_PEER_DATA to the siconos folder to include them)")
    return peers + [E.random_problem(f, n, i) for f in E.FAMILIES for n in config.peer_sizes
                    for i in range(config.peer_instances)]


FIXED_COST_PROBLEMS = tuple(
    E.Problem(name, "fixed", 2, np.array([[2.0, 1.0], [1.0, 2.0]]), np.array(q))
    for name, q in (("2x2, two pivots", [-5.0, -6.0]), ("2x2, q >= 0", [1.0, 2.0])))
"""n = 2 problems on which a call's time is almost all fixed cost (dispatch, checks, result)."""


def compare_lemke(problems: Sequence[E.Problem], plan: TimingPlan, log: Log
                  ) -> list[dict[str, Any]]:  # fmt: skip
    """Our Lemke (driver and compiled entry) against QuantEcon's, interleaved, per problem."""
    keys = dict(zip(ENTRY_KEYS, (E.DRIVER_LEMKE, E.KERNEL, E.QUANTECON), strict=True))
    rows = []
    for problem in problems:
        measured = time_problem(problem, list(keys.values()), plan)
        row = {"name": problem.name, "family": problem.family, "n": problem.n,
               **{key: measured[entry.name] for key, entry in keys.items()}}
        row.update({f"ratio_{key}": row[key]["time"]["median_s"]
                    / row["quantecon"]["time"]["median_s"] for key in ("driver", "kernel")})
        rows.append(row)
        log(f"{problem.name} (n={problem.n}): " + ", ".join(
            f"{key} {row[key]['time']['median_s'] * 1e6:.3g} µs" for key in keys)
            + f"; QE status {row['quantecon']['outcome']['status']}")
    return rows


def run(config: BenchConfig, output: Path, quick: bool) -> str:
    """Run the whole benchmark, write the outputs and return its summary (Markdown)."""
    with report.study("solvers", output, {"quick": quick, **asdict(config)}) as (record, log, _):
        record["first_call"] = measure_first_calls(config, log)
        problem = E.random_problem("spd", 5, 0)  # every entry once: no timed compile or load
        for entry in [E.KERNEL, E.QUANTECON, *(E.driver_entry(m) for m in E.LCP_METHODS)]:
            entry.solve(problem.M, problem.q)
        record["fixed_cost"] = [
            {k: v for k, v in row.items() if not k.startswith(("family", "ratio"))}
            for row in compare_lemke(FIXED_COST_PROBLEMS, config.peer_plan, log)]
        records = size_study(config, log)
        aggregates = aggregate_size_study(records)
        record["size_study"] = {"records": records, "aggregates": aggregates}
        rows = compare_lemke(comparison_problems(config, log), config.peer_plan, log)
        record["quantecon_comparison"] = {"quantecon_max_iter": E.QUANTECON_MAX_ITER,
                                          "problems": rows, "median_ratios": ratio_summary(rows)}
        plot_by_entry(aggregates, output / "solvers_time_vs_size.png", "time_median_s")
        plot_by_entry(aggregates, output / "solvers_residual_vs_size.png", "residual_max")
        plot_ratios(rows, output / "lemke_vs_quantecon.png")
    return summary(record, ("numpy", "numba", "quantecon"))


def aggregate_size_study(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Combine the instances of each (family, n, entry) of the work-size study."""
    frame = pd.json_normalize(list(records))
    rows = frame.groupby(["family", "n", "entry"], sort=False).agg(
        time_median_s=("time.median_s", "median"), time_min_s=("time.median_s", "min"),
        time_max_s=("time.median_s", "max"), residual_max=("outcome.residual", "max"),
        iterations_median=("outcome.iterations", "median"), solved=("outcome.success", "sum"),
        instances=("entry", "size"))
    return rows.reset_index().astype(object).to_dict("records")


def ratio_summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Median time ratios ours/QuantEcon over problem sets, for both of our entry points."""
    solved = [r for r in rows if all(r[k]["outcome"]["success"] for k in ENTRY_KEYS)]
    sets = {
        "Siconos peer files": [r for r in rows if r["family"] == "siconos"],
        "random (spd + contact)": [r for r in rows if r["family"] != "siconos"],
        "random spd (target: driver / QE <= 1)": [r for r in rows if r["family"] == "spd"],
        "random contact": [r for r in rows if r["family"] == "contact"],
        "Siconos peer files solved by all three": [r for r in solved if r["family"] == "siconos"],
    }
    return [{"set": name, "problems": len(members),
             "median_ratio_driver": float(np.median([r["ratio_driver"] for r in members])),
             "median_ratio_kernel": float(np.median([r["ratio_kernel"] for r in members]))}
            for name, members in sets.items() if members]


def plot_by_entry(aggregates: Sequence[dict[str, Any]], path: Path, value: str) -> None:
    """One log-log panel per family, one line per entry, against n.

    ``value`` is ``time_median_s`` (band: min..max over instances) or ``residual_max``.
    """
    families = list(dict.fromkeys(r["family"] for r in aggregates))
    fig, axes = plt.subplots(1, len(families), figsize=(5.5 * len(families), 4.2), sharey=True)
    axes = list(np.atleast_1d(axes))
    floored = [{**r, value: max(r[value], RESIDUAL_FLOOR)} for r in aggregates]
    for ax, family in zip(axes, families, strict=True):
        log_lines(ax, [r for r in floored if r["family"] == family], "n", value, "entry",
                  ("time_min_s", "time_max_s") if value == "time_median_s" else None,
                  label=lambda e: ENTRY_TITLES.get(e, e), dashed=lambda e: e == "quantecon")
        if value == "residual_max":
            ax.axhline(1e-10, color="grey", lw=0.8, ls=":", label="tol 1e-10")
        ax.set_title(f"family {family!r}")
        ax.set_xlabel("n")
    axes[0].set_ylabel("time per solve (s)" if value == "time_median_s"
                       else "largest residual (0 drawn at 1e-18)")
    axes[-1].legend(fontsize=8)
    save_figure(fig, path)


def plot_ratios(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the time ratio ours/QuantEcon per problem, for both entry points."""
    fig, ax = plt.subplots(figsize=(9.0, 0.22 * len(rows) + 1.8))
    ax.axvline(1.0, color="k", lw=0.8)
    bars(ax, [_ratio_label(r) for r in rows], {
        "solve_lcp driver / QE": [r["ratio_driver"] for r in rows],
        "lemke_solve / QE": [r["ratio_kernel"] for r in rows]},
        "time ratio ours / QuantEcon lcp_lemke (< 1: ours faster)")
    save_figure(fig, path)


def _ratio_label(row: dict[str, Any]) -> str:
    """Bar label: the problem, its size, and both statuses when either entry failed."""
    def short(status: str) -> str:  # "RAY_TERMINATION" -> "ray termination"; "1 (x)" -> "x"
        return (status.split("(", 1)[1].rstrip(")") if "(" in status
                else status.lower().replace("_", " "))

    label = f"{row['name']} (n={row['n']})"
    ours, theirs = row["kernel"]["outcome"], row["quantecon"]["outcome"]
    if not (ours["success"] and theirs["success"]):
        label += f" [ours: {short(ours['status'])}; QE: {short(theirs['status'])}]"
    return label


def main(argv: Sequence[str] | None = None) -> None:
    """Command-line entry point."""
    args = timing.arguments(__doc__, argv)
    print(run(QUICK if args.quick else FULL, args.output, args.quick))


if __name__ == "__main__":
    main()
