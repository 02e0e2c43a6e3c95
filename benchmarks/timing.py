"""Wall-clock timing: interleaved rounds with adaptive repeats, first-call probes, machine info.

``time_interleaved`` runs its callables in rounds A B C, A B C, ... (after one untimed warm-up
call each), so a phase of load on the shared machine hits every entry it compares alike.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import math
import os
import platform
import subprocess
import sys
import time
import timeit
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs.provenance import git_commit

Log = Callable[[str], None]
"""A progress log: one call per line."""


@dataclass(frozen=True)
class TimingPlan:
    """How long to time one problem."""

    budget_s: float
    min_rounds: int
    max_rounds: int
    min_batch_s: float = 2e-4


@dataclass(frozen=True)
class Timed:
    """One callable's warm-up ``result`` and time per call [s] over ``rounds`` of ``number``."""

    result: Any
    median_s: float
    min_s: float
    q1_s: float
    q3_s: float
    rounds: int
    number: int

    def summary(self, operations_per_call: int = 1) -> dict[str, float | int]:
        """The times as a JSON-ready dict, per operation (``operations_per_call`` per call)."""
        per = operations_per_call
        return {"median_s": self.median_s / per, "min_s": self.min_s / per,
                "q1_s": self.q1_s / per, "q3_s": self.q3_s / per, "rounds": self.rounds,
                "number": self.number}


def timed_call(call: Callable[[], Any]) -> tuple[Any, float]:
    """Call once; return (result, wall-clock seconds)."""
    start = time.perf_counter()
    result = call()
    return result, time.perf_counter() - start


def time_interleaved(calls: Mapping[str, Callable[[], Any]], plan: TimingPlan) -> dict[str, Timed]:
    """Time callables (name -> zero-argument call) in interleaved rounds; name -> ``Timed``.

    Each gets one untimed warm-up call, then per round a batch of ``number`` calls lasting at
    least ``plan.min_batch_s``; the time per call is the median over rounds of batch / number.
    """
    warm = {name: timed_call(call) for name, call in calls.items()}
    numbers = {name: max(1, math.ceil(plan.min_batch_s / max(seconds, 1e-9)))
               for name, (_, seconds) in warm.items()}
    slowest = max(numbers[name] * warm[name][1] for name in calls)
    rounds = min(plan.max_rounds, max(plan.min_rounds, int(plan.budget_s / max(slowest, 1e-9))))
    samples: dict[str, list[float]] = {name: [] for name in calls}
    timers = {name: timeit.Timer(call, setup="gc.enable()") for name, call in calls.items()}
    for _ in range(rounds):
        for name, timer in timers.items():
            samples[name].append(timer.timeit(numbers[name]) / numbers[name])
    quartiles = {name: np.percentile(values, [25, 50, 75]) for name, values in samples.items()}
    return {name: Timed(warm[name][0], float(q[1]), min(samples[name]), float(q[0]), float(q[2]),
                        rounds, numbers[name]) for name, q in quartiles.items()}


ROOT = Path(__file__).resolve().parents[1]
"""The repository's root, where ``python -m benchmarks.NAME`` runs."""


def fresh_python(*args: str, cwd: Path = ROOT, **env: str | Path | None
                 ) -> subprocess.CompletedProcess[str]:  # fmt: skip
    """``python ARGS`` in a fresh interpreter in ``cwd``, ``env`` (but None or "") over ours."""
    environment = {**os.environ, **{key: str(value) for key, value in env.items() if value}}
    return subprocess.run([sys.executable, *args], cwd=cwd, env=environment, capture_output=True,
                          text=True, check=False)


def _cpu_model() -> str:
    """CPU model name from /proc/cpuinfo, falling back to ``platform.processor()``."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor()


VERSIONED_PACKAGES = ("numpy", "scipy", "numba", "llvmlite", "quantecon", "mdi-envs")
"""Distributions whose versions ``machine_info`` records by default."""


def load_average() -> list[float] | None:
    """The 1/5/15-minute load averages, where the platform has them."""
    return list(os.getloadavg()) if hasattr(os, "getloadavg") else None


def speed_probe(samples: int = 200, number: int = 5000) -> dict[str, float]:
    """How fast this machine runs right now: a compiled no-op called from Python."""
    from numba import njit  # here: the timing helpers do not otherwise need numba

    @njit
    def no_op(array: np.ndarray) -> float:
        return array[0]

    array = np.zeros(1)
    no_op(array)
    times = []
    for _ in range(samples):
        start = time.perf_counter()
        for _ in range(number):
            no_op(array)
        times.append((time.perf_counter() - start) / number * 1e6)
    fastest = min(times)
    return {"fastest_us": fastest, "median_us": float(np.median(times)),
            "slow_fraction": sum(t > 1.5 * fastest for t in times) / samples}


def _version(name: str) -> str | None:
    with contextlib.suppress(metadata.PackageNotFoundError):
        return metadata.version(name)
    return None


def load_text() -> str:
    """The 1-minute load average, for progress lines."""
    load = load_average()
    return f"{load[0]:.2f}" if load else "n/a"


def checkpoint(record: dict[str, Any], section: str, progress: Progress) -> None:
    """Append the load average at the start of ``section`` to ``record["load_log"]``."""
    record.setdefault("load_log", []).append(
        {"section": section, "elapsed_s": progress.elapsed, "load_average": load_average()})


def finish(record: dict[str, Any], elapsed_s: float, speed: bool = False) -> None:
    """Close a run's record: load average (and speed probe) at the end, ``run_time_s``."""
    record["machine"]["load_average_at_end"] = load_average()
    if speed:
        record["machine"]["speed_probe_at_end"] = speed_probe()
    record["run_time_s"] = elapsed_s


def arguments(doc: str | None, argv: Sequence[str] | None, *extra: tuple[str, dict[str, Any]],
              quick: bool = True) -> argparse.Namespace:
    """A benchmark's command line: ``--output``, ``--quick`` and ``extra`` (flag, options)."""
    parser = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("benchmarks/results"),
                        help="output folder (default: benchmarks/results)")
    if quick:
        parser.add_argument("--quick", action="store_true", help="small grids and budgets")
    for flag, options in extra:
        parser.add_argument(flag, **options)
    return parser.parse_args(argv)


class Progress:
    """Progress lines on stderr, stamped with the seconds since the start of the run."""

    def __init__(self) -> None:
        self.start = time.perf_counter()

    @property
    def elapsed(self) -> float:
        """Seconds since construction."""
        return time.perf_counter() - self.start

    def __call__(self, message: str) -> None:
        """Print one progress line."""
        print(f"[{self.elapsed:6.1f} s] {message}", file=sys.stderr, flush=True)


def machine_info(packages: tuple[str, ...] = VERSIONED_PACKAGES) -> dict[str, Any]:
    """Platform, CPU, load, versions of ``packages`` and the date, for the JSON record."""
    return {
        "date": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu_model": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "cpu_affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "load_average_at_start": load_average(),
        "speed_probe_at_start": speed_probe(),
        "versions": {name: _version(name) for name in packages},
        "git_commit": git_commit(),
    }
