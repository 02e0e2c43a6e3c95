"""Start-up time: a fresh interpreter to its first env step returned (``mdi-envs bench startup``).

Each case runs ``probes.startup`` in a new process through ``gym.make``, ``gym.make_vec`` or an SB3
``SubprocVecEnv``, warm (cache filled by ``mdi-envs compile all``) and, in the full run, cold;
beside Acrobot-v1 and InvertedDoublePendulum-v5. Writes ``startup.json`` and ``startup.png``.
``--python-path DIR`` runs the probes on the package in DIR.
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import Any

from benchmarks import report
from benchmarks.probes import FLOOR
from benchmarks.timing import VERSIONED_PACKAGES, arguments, fresh_python, timed_call

REFERENCES = ("Acrobot-v1", "InvertedDoublePendulum-v5")
"""Gymnasium's classic-control and MuJoCo envs measured beside ours in the same run, and (last
row, ``probes.FLOOR``) the floor of any numba env: one trivial cached kernel's load."""
ENTRIES = ("single", "vector", "subproc")
QUICK_IDS = ("mdi_envs/BlockableManipulator-v1", "Acrobot-v1")
"""The ids ``--quick`` probes (warm, once, gym.make and gym.make_vec), besides the floor."""
TARGET_RATIO = 2.0  # Warm start-up target: within this factor of Acrobot-v1's, entry by entry.


def time_to_first_step(entry: str, env_id: str, cache: Path | None,
                       python_path: Path | None = None) -> dict[str, Any]:
    """Seconds from starting a fresh interpreter to its first ``step`` returned, and phases.

    ``cache``: the kernel cache, ``python_path``: PYTHONPATH (None: as in this interpreter).
    """
    started = time.time()
    process = fresh_python("-m", "benchmarks.probes", "startup", entry, env_id,
                           MDI_ENVS_CACHE_DIR=cache, PYTHONPATH=python_path)
    lines = [line for line in process.stdout.splitlines() if line.startswith("{")]
    if process.returncode != 0 or not lines:
        return {"error": (process.stderr.strip().splitlines() or ["no output"])[-1]}
    report = json.loads(lines[-1])
    return {"seconds": report["done"] - started, "phases": report["phases"]}


def compile_all(cache: Path | None, python_path: Path | None = None) -> dict[str, Any]:
    """Wall seconds of ``mdi-envs compile all`` in a fresh interpreter, and its exit code."""
    process, seconds = timed_call(partial(
        fresh_python, "-c", "import sys; from mdi_envs.cli import main; "
        "sys.exit(main(['compile', 'all']))", MDI_ENVS_CACHE_DIR=cache, PYTHONPATH=python_path))
    return {"seconds": seconds, "returncode": process.returncode,
            "output": process.stdout.strip().splitlines()[-6:]}


def _summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    seconds = [run["seconds"] for run in runs if "seconds" in run]
    errors = [run["error"] for run in runs if "error" in run]
    return {"runs": runs, **({"median": statistics.median(seconds), "min": min(seconds)}
                             if seconds else {}), **({"errors": errors} if errors else {})}


def run(quick: bool, output: Path, python_path: Path | None = None,
        repeats: int = 5) -> dict[str, Any]:
    """Run the study, write ``startup.json`` and ``startup.png``; returns the record."""
    from mdi_envs import ENV_IDS

    ids = [*(QUICK_IDS if quick else (*ENV_IDS, *REFERENCES)), FLOOR]
    entries = ENTRIES[:2] if quick else ENTRIES
    config = {"quick": quick, "python_path": str(python_path) if python_path else None,
              "target_ratio": TARGET_RATIO}
    with (report.study("startup", output, config) as (record, log, _),
          tempfile.TemporaryDirectory(prefix="mdi-envs-cache-") as scratch):
        cache = None if quick else Path(scratch) / "warm"
        log(f"mdi-envs compile all ({'user cache' if quick else 'empty cache'})")
        record["compile_all"] = compile_all(cache, python_path)
        log(f"  {record['compile_all']['seconds']:.1f} s")
        if not quick:
            record["compile_all_warm"] = compile_all(cache, python_path)
            log(f"  again, warm: {record['compile_all_warm']['seconds']:.1f} s")
        warm_runs: dict[str, list[dict[str, Any]]] = {}
        for repeat in range(1 if quick else repeats):
            for env_id in ids:
                for entry in entries[:1] if env_id == FLOOR else entries:
                    key = f"{env_id} {entry}"
                    log(f"warm {repeat + 1}: {key}")
                    warm_runs.setdefault(key, []).append(
                        time_to_first_step(entry, env_id, cache, python_path))
        record["warm"] = {key: _summary(runs) for key, runs in warm_runs.items()}
        record["cold"] = {}
        if not quick:
            for env_id in ENV_IDS:
                for entry in ENTRIES[:2]:
                    log(f"cold: {env_id} {entry}")
                    empty = Path(tempfile.mkdtemp(dir=scratch, prefix="cold-"))
                    record["cold"][f"{env_id} {entry}"] = _summary(
                        [time_to_first_step(entry, env_id, empty, python_path)])
        record["ratios_to_acrobot"] = _ratios(record["warm"], entries)
        record["targets"] = _targets(record, ENV_IDS, entries)
        _plot(record, ids, entries, output / "startup.png")
    return record


def _ratios(warm: dict[str, Any], entries: Sequence[str]) -> dict[str, float]:
    """Warm median of every case over Acrobot-v1's in the same entry."""
    references = {entry: warm.get(f"Acrobot-v1 {entry}", {}).get("median") for entry in entries}
    return {key: summary["median"] / references[entry] for entry in entries
            for key, summary in warm.items()
            if key.endswith(f" {entry}") and references[entry] and "median" in summary}


def _targets(record: dict[str, Any], env_ids: Sequence[str],
             entries: Sequence[str]) -> list[dict[str, Any]]:
    """The start-up targets (``benchmarks.report.target_row``)."""
    config = record["config"]
    ratios = {key: ratio for key, ratio in record["ratios_to_acrobot"].items()
              if key.split(" ")[0] in env_ids and key.rsplit(" ", 1)[1] in ("single", "vector")}
    targets = []
    if ratios:
        worst = max(ratios, key=ratios.__getitem__)
        targets.append(report.target_row(
            "warm start to the first env step, every id, gym.make and gym.make_vec: time / "
            "Acrobot-v1's (worst case)", "≤", config["target_ratio"], "×", ratios[worst],
            f"worst: {worst}, {record['warm'][worst]['median']:.2f} s"))
    if not config["quick"]:
        seconds = record["compile_all"]["seconds"]
        targets.append(report.target_row(
            "mdi-envs compile all on an empty cache", "≤", 30.0, "s", seconds,
            f"{record['machine']['cpu_count']} cores",
            seconds <= 30.0 and record["compile_all"]["returncode"] == 0))
    return targets


def _plot(record: dict[str, Any], ids: Sequence[str], entries: Sequence[str],
          path: Path) -> None:
    """Bars per id (log): the warm start of each entry and the cold start of ``single``."""
    series = {f"warm, {entry}": [record["warm"].get(f"{i} {entry}", {}).get("median") for i in ids]
              for entry in entries}
    colds = [record["cold"].get(f"{i} single", {}).get("median") for i in ids]
    if any(colds):
        series["cold (empty cache), single"] = colds
    figure, axis = report.plt.subplots(figsize=(9, 0.25 * len(ids) * len(series) + 1.8))
    ratio = record["config"]["target_ratio"]
    if acrobot := record["warm"].get("Acrobot-v1 single", {}).get("median"):
        axis.axvline(ratio * acrobot, color="k", linestyle="--", linewidth=1,
                     label=f"{ratio:g}× Acrobot-v1 (single, warm)")
    report.bars(axis, [i.removeprefix("mdi_envs/") for i in ids], series,
                "fresh interpreter start → first step returned [s]"
                + (" (quick: warm, one run)" if record["config"]["quick"] else ""))
    report.save_figure(figure, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point."""
    args = arguments(__doc__, argv, ("--python-path", {"type": Path, "help": "probe the package "
                                                       "in this folder (PYTHONPATH)"}),
                     ("--repeats", {"type": int, "default": 5, "help": "warm repetitions"}))
    record = run(args.quick, args.output, args.python_path, args.repeats)
    print(report.summary(record, VERSIONED_PACKAGES))
    failed = any("errors" in summary for summary in record["warm"].values())
    return 1 if failed or record["compile_all"]["returncode"] != 0 else 0


if __name__ == "__main__":
    sys.exit(main())
