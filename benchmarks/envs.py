"""Environment benchmark: ``env.step`` µs through ``gym.make`` and vector-env throughput.

``python -m benchmarks.envs [--output DIR] [--quick] [--cpu N]`` writes ``envs.json``,
``envs_step.png`` and ``envs_vector.png``: first calls, ``env.step`` of every id and of Acrobot-v1
and InvertedDoublePendulum-v5 (wrapped and unwrapped, interleaved), and ``gym.make_vec`` steps/s
against N beside Acrobot in ``"sync"`` mode. The process is pinned to one CPU (``--cpu -1``: not).
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numba

import mdi_envs
from benchmarks import report, timing
from benchmarks.report import bars, log_lines, plt, save_figure, summary
from benchmarks.timing import Log, TimingPlan

ACROBOT, MUJOCO_PEER = "Acrobot-v1", "InvertedDoublePendulum-v5"
MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
VERSIONED = ("numpy", "numba", "llvmlite", "gymnasium", "mujoco", "mdi-envs")
TARGETS = {"manipulator_step_us": 10.0, "speedup_vs_acrobot": 3.0,
           "manipulator_physics_steps_per_s": 5e6, "manipulator_vector_copies": 4096}
UNITS = {"*_s": "seconds", "*_us": "microseconds", "*_per_s": "per second (wall clock)",
         "ratio_*": "peer time / our time (> 1: ours faster)",
         "frame_skip": "physics steps per env step", "num_envs": "copies in one vector env",
         "rounds, number": "timed samples, calls per sample",
         "steps_per_call": "env.step calls per timed call (times are per step)"}


@dataclass(frozen=True)
class EnvsConfig:
    """Our env ids (None: all) and peers, vector N, action samples and timing of one run."""

    env_ids: tuple[str, ...] | None
    peers: tuple[str, ...]
    copies: tuple[int, ...]
    action_samples: int
    step_plan: TimingPlan
    vector_plan: TimingPlan
    sync_peer: str | None = ACROBOT
    sync_max_copies: int = 256
    cpu: int | None = 0
    seed: int = 0


FULL = EnvsConfig(
    env_ids=None, peers=(ACROBOT, MUJOCO_PEER), copies=(1, 4, 16, 64, 256, 1024, 4096),
    action_samples=1024,
    step_plan=TimingPlan(budget_s=2.0, min_rounds=21, max_rounds=301, min_batch_s=5e-3),
    vector_plan=TimingPlan(budget_s=2.0, min_rounds=21, max_rounds=61, min_batch_s=5e-3))
QUICK = EnvsConfig(
    env_ids=(MANIPULATOR,), peers=(ACROBOT,), copies=(1, 16, 256), action_samples=256,
    step_plan=TimingPlan(budget_s=0.2, min_rounds=9, max_rounds=51, min_batch_s=2e-3),
    vector_plan=TimingPlan(budget_s=0.1, min_rounds=5, max_rounds=15, min_batch_s=2e-3))


def frame_skip(env: Any) -> int:
    """Physics steps per env step: ``scene.frame_skip`` for ours, ``frame_skip`` (MuJoCo) else 1."""
    inner = (env.envs[0] if hasattr(env, "envs") else env).unwrapped
    return int(getattr(getattr(inner, "scene", None), "frame_skip",
                       getattr(inner, "frame_skip", 1)))


def _wrapper_chain(env: Any) -> list[str]:
    """Class names from the outermost wrapper down to the env."""
    names = [type(env).__name__]
    while isinstance(env, gym.Wrapper):
        env = env.env
        names.append(type(env).__name__)
    return names


def _sample_actions(space: gym.Space, count: int, seed: int) -> list[Any]:
    """``count`` actions sampled before any timing (the timed loop only indexes them)."""
    space.seed(seed)
    return [space.sample() for _ in range(count)]


STEPS_PER_CALL = 64  # ``env.step`` calls per timed call of a ``StepLoop``.
STATISTICS = ("median", "q1", "q3", "min")  # of the times over rounds, as in ``Timed.summary``


class StepLoop:
    """``steps_per_call`` calls of ``env.step`` with pre-sampled actions, reset when one ends."""

    def __init__(self, env: Any, actions: list[Any], max_steps: int | None = None,
                 steps_per_call: int = STEPS_PER_CALL) -> None:
        self.env, self.max_steps, self.steps_per_call = env, max_steps, steps_per_call
        self.actions = itertools.cycle(actions)
        self.episode_steps = self.steps = self.episodes = 0

    def __call__(self) -> None:
        """Step ``steps_per_call`` times (and reset whenever an episode ends)."""
        env, max_steps = self.env, self.max_steps
        episode_steps = self.episode_steps
        for action in itertools.islice(self.actions, self.steps_per_call):
            _, _, terminated, truncated, _ = env.step(action)
            episode_steps += 1
            if terminated or truncated or episode_steps == max_steps:
                env.reset()
                self.episodes += 1
                episode_steps = 0
        self.episode_steps = episode_steps
        self.steps += self.steps_per_call


def _error_text(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}"


def _make_single(env_id: str, ours: bool, seed: int, samples: int
                 ) -> tuple[dict[str, Any], list[Any]]:
    """Make the env twice (timed ``gym.make`` and unwrapped) and time the first calls."""
    env, make_s = timing.timed_call(lambda: gym.make(env_id))
    reset_s = timing.timed_call(lambda: env.reset(seed=seed))[1]
    actions = _sample_actions(env.action_space, samples, seed)
    first_step_s = timing.timed_call(lambda: env.step(actions[0]))[1]
    env.reset(seed=seed)
    bare = gym.make(env_id).unwrapped
    bare.reset(seed=seed)
    bare.step(actions[0])
    bare.reset(seed=seed)
    max_steps = env.spec.max_episode_steps if env.spec is not None else None
    record = {"env_id": env_id, "ours": ours, "wrappers": _wrapper_chain(env),
              "frame_skip": frame_skip(env),
              "dt_s": float(env.unwrapped.dt) if hasattr(env.unwrapped, "dt") else None,
              "max_episode_steps": max_steps, "action_space": str(env.action_space),
              "first_make_s": make_s, "first_reset_s": reset_s, "first_step_s": first_step_s}
    return record, [StepLoop(env, actions), StepLoop(bare, actions, max_steps)]


def single_env_study(env_ids: Sequence[str], peers: Sequence[str], config: EnvsConfig,
                     log: Log) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """``env.step`` through ``gym.make`` and unwrapped, interleaved; ours with ratios to peers."""
    records, unavailable = [], []
    loops: dict[str, StepLoop] = {}
    for env_id in (*env_ids, *peers):
        log(f"making {env_id} (first make/reset/step; numba compiles ours) ...")
        try:
            record, (wrapped, bare) = _make_single(env_id, env_id in env_ids, config.seed,
                                                   config.action_samples)
        except Exception as error:  # noqa: BLE001  (any failure of a peer is recorded)
            unavailable.append({"env_id": env_id, "error": _error_text(error)})
            log(f"  {env_id} not measured: {unavailable[-1]['error']}")
            continue
        records.append(record)
        loops[f"{env_id}|gym.make"], loops[f"{env_id}|unwrapped"] = wrapped, bare
    log(f"single env: {len(loops)} step loops, interleaved; load {timing.load_text()} ...")
    timed = timing.time_interleaved(loops, config.step_plan)
    for record in records:
        for entry in ("gym.make", "unwrapped"):
            loop = loops[f"{record['env_id']}|{entry}"]
            summary = timed[f"{record['env_id']}|{entry}"].summary(loop.steps_per_call)
            record[entry] = {
                **{f"{stat}_us": summary[f"{stat}_s"] * 1e6 for stat in STATISTICS},
                "rounds": summary["rounds"], "number": summary["number"],
                "steps_per_call": loop.steps_per_call, "steps_total": loop.steps,
                "episodes_ended": loop.episodes}
            loop.env.close()
        record["per_physics_step_us"] = record["gym.make"]["median_us"] / record["frame_skip"]
    peers = [r for r in records if not r["ours"]]
    for ours in (r for r in records if r["ours"]):  # peer time / ours, medians and fastest
        ours["ratios"] = {peer["env_id"]: {
            "ratio_median": peer["gym.make"]["median_us"] / ours["gym.make"]["median_us"],
            "ratio_fastest": peer["gym.make"]["min_us"] / ours["gym.make"]["min_us"],
            "ratio_median_unwrapped": (peer["unwrapped"]["median_us"]
                                       / ours["unwrapped"]["median_us"])} for peer in peers}
    return records, unavailable


def _vector_entry(env_id: str, mode: str, num_envs: int, config: EnvsConfig
                  ) -> tuple[Any, Callable[[], None], dict[str, Any]]:
    """A reset vector env, a call stepping every copy once, and its description.

    Each call steps with the next pre-sampled action batch (the env resets copies itself).
    """
    start = time.perf_counter()
    env = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode=mode)
    env.reset(seed=config.seed)
    samples = max(2, min(config.action_samples, 16))
    batches = itertools.cycle(_sample_actions(env.action_space, samples, config.seed))

    def loop() -> None:
        env.step(next(batches))

    loop()
    setup_s = time.perf_counter() - start
    return env, loop, {"env_id": env_id, "mode": mode, "num_envs": num_envs,
                  "frame_skip": frame_skip(env), "setup_s": setup_s,
                  "action_batches": samples}


def vector_study(env_ids: Sequence[str], config: EnvsConfig, log: Log
                 ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Env-steps/s and physics steps/s of each vector env per N, interleaved per N."""
    rows: list[dict[str, Any]] = []
    unavailable: list[dict[str, Any]] = []
    failed: set[str] = set()
    entries = [(env_id, "vector_entry_point") for env_id in env_ids]
    if config.sync_peer is not None:
        entries.append((config.sync_peer, "sync"))
    for n in config.copies:
        envs: dict[str, Any] = {}
        loops: dict[str, Callable[[], None]] = {}
        meta: dict[str, dict[str, Any]] = {}
        for env_id, mode in entries:
            key = f"{env_id}|{mode}"
            if key in failed or (mode == "sync" and n > config.sync_max_copies):
                continue
            try:
                envs[key], loops[key], meta[key] = _vector_entry(env_id, mode, n, config)
            except Exception as error:  # noqa: BLE001  (recorded, the run continues)
                failed.add(key)
                unavailable.append({"env_id": env_id, "mode": mode, "num_envs": n,
                                    "error": _error_text(error)})
                log(f"  {key} N = {n} not measured: {unavailable[-1]['error']}")
        if not loops:
            continue
        measured = []
        rates = (("", "median"), ("_q1", "q3"), ("_q3", "q1"), ("_best", "min"))  # time quantile
        for key, value in timing.time_interleaved(loops, config.vector_plan).items():
            times, skip = value.summary(), meta[key]["frame_skip"]
            measured.append({
                **meta[key], "call": times,
                **{f"env_steps_per_s{k}": n / times[f"{stat}_s"] for k, stat in rates},
                "per_env_step_us": times["median_s"] / n * 1e6,
                **{f"physics_steps_per_s{k}": n / times[f"{stat}_s"] * skip for k, stat in rates}})
            envs[key].close()
        rows += measured
        log(f"vector N = {n}: " + ", ".join(
            f"{short_name(r['env_id'])} ({r['mode']}) {r['env_steps_per_s']:.3g} env-steps/s"
            for r in measured) + f"; load {timing.load_text()}")
    return rows, unavailable


def evaluate_targets(single: Sequence[dict[str, Any]], vector: Sequence[dict[str, Any]]
                     ) -> list[dict[str, Any]]:
    """The targets against the measurements (``met`` None where not measured)."""
    manipulator = next((r for r in single if r["env_id"] == MANIPULATOR), None)
    step = manipulator["gym.make"]["median_us"] if manipulator else None
    targets = [report.target_row("manipulator env.step through gym.make (median)", "≤",
                            TARGETS["manipulator_step_us"], "µs", step,
                            "" if step is None else
                            f"fastest rounds {manipulator['gym.make']['min_us']:.1f} µs, "
                            f"unwrapped {manipulator['unwrapped']['median_us']:.1f} µs")]
    for record in (r for r in single if r["ours"]):
        ratio = record["ratios"].get(ACROBOT)
        targets.append(report.target_row(
            f"{short_name(record['env_id'])} env.step ≥ 3× faster than {ACROBOT} "
            "(Acrobot time / ours, medians)", "≥", TARGETS["speedup_vs_acrobot"], "×",
            None if ratio is None else ratio["ratio_median"],
            "" if ratio is None else f"fastest rounds {ratio['ratio_fastest']:.2f}×, "
            f"unwrapped {ratio['ratio_median_unwrapped']:.2f}×"))
    rows = [r for r in vector if r["env_id"] == MANIPULATOR and r["mode"] == "vector_entry_point"]
    wanted = TARGETS["manipulator_vector_copies"]
    at = [r for r in rows if r["num_envs"] == wanted]
    best = max(rows, key=lambda r: r["physics_steps_per_s"]) if rows else None
    note = ("" if best is None else
            f"best over N: {best['physics_steps_per_s']:.3g} at N = {best['num_envs']}")
    if not at and rows:
        largest = max(rows, key=lambda r: r["num_envs"])
        note = (f"N = {wanted} not run (quick); at N = {largest['num_envs']}: "
                f"{largest['physics_steps_per_s']:.3g}; " + note)
    targets.append(report.target_row(
        f"manipulator vector env physics steps/s at num_envs = {wanted}, one core", "≥",
        TARGETS["manipulator_physics_steps_per_s"], "1/s",
        at[0]["physics_steps_per_s"] if at else None, note))
    return targets


def _pin(cpu: int | None) -> tuple[set[int] | None, dict[str, Any]]:
    """Pin the process to ``cpu``; return (the previous affinity or None, a JSON note)."""
    if cpu is None or not hasattr(os, "sched_setaffinity"):
        return None, {"pinned": False, "cpus": sorted(os.sched_getaffinity(0))
                      if hasattr(os, "sched_getaffinity") else None}
    previous = os.sched_getaffinity(0)
    try:
        os.sched_setaffinity(0, {cpu})
    except OSError as error:
        return None, {"pinned": False, "error": _error_text(error), "cpus": sorted(previous)}
    return previous, {"pinned": True, "cpus": sorted(os.sched_getaffinity(0))}


def run(config: EnvsConfig, output: Path, quick: bool, log: Log | None = None) -> str:
    """Run the whole benchmark, write the outputs and return its summary (Markdown)."""
    env_ids = tuple(config.env_ids if config.env_ids is not None else mdi_envs.ENV_IDS)
    settings = {"quick": quick, "env_ids": env_ids,
                **{k: v for k, v in asdict(config).items() if k != "env_ids"}}
    previous, pinning = _pin(config.cpu)
    try:
        with report.study("envs", output, settings, VERSIONED, True, log) as (record, log, clock):
            record.update({"pinning": pinning, "numba_threading": {
                "num_threads": numba.config.NUMBA_NUM_THREADS,
                "threading_layer": numba.config.THREADING_LAYER, "parallel_kernels_used": False},
                "units": UNITS, "targets_brief": TARGETS, "notes": []})
            log(f"pinned to {pinning['cpus']}; load {timing.load_text()}")
            timing.checkpoint(record, "single env", clock)
            single, unavailable = single_env_study(env_ids, config.peers, config, log)
            timing.checkpoint(record, "vector env", clock)
            vector, vector_unavailable = vector_study(env_ids, config, log)
            timing.checkpoint(record, "end", clock)
            for item in (*unavailable, *vector_unavailable):
                mode = f" ({item['mode']})" if "mode" in item else ""
                record["notes"].append(f"{item['env_id']}{mode} not measured: {item['error']}")
            record.update({"single_env": single, "unavailable": unavailable,
                           "vector_env": vector, "vector_unavailable": vector_unavailable,
                           "targets": evaluate_targets(single, vector)})
            plot_step(single, unavailable, TARGETS, output / "envs_step.png")
            plot_vector(vector, TARGETS, output / "envs_vector.png")
    finally:
        if previous is not None:
            os.sched_setaffinity(0, previous)
    return summary(record, ("numpy", "numba", "gymnasium", "mujoco"))


def short_name(env_id: str) -> str:
    """A short label: ``mdi_envs/BlockableManipulator-v0`` -> ``BlockableManipulator``."""
    return env_id.split("/")[-1].removesuffix("-v0") if env_id.startswith("mdi_envs/") else env_id


def plot_step(single: Sequence[dict[str, Any]], unavailable: Sequence[dict[str, Any]],
              targets: Mapping[str, float], path: Path) -> None:
    """Bars of ``env.step`` µs per env (gym.make and unwrapped), with the targets as lines."""
    labels = [short_name(r["env_id"]) + ("" if r["ours"] else " (peer)") for r in single]
    labels += [f"{short_name(u['env_id'])} (peer, not measured: {u['error'][:40]})"
               for u in unavailable]
    fig, ax = plt.subplots(figsize=(8.5, 0.5 * len(labels) + 1.8))
    ax.axvline(targets["manipulator_step_us"], color="tab:green", ls=":", lw=1.2,
               label=f"target: manipulator ≤ {targets['manipulator_step_us']:g} µs")
    acrobot = [r for r in single if r["env_id"] == "Acrobot-v1"]
    if acrobot:
        bound = acrobot[0]["gym.make"]["median_us"] / targets["speedup_vs_acrobot"]
        ax.axvline(bound, color="tab:red", ls="--", lw=1.0, label=f"target: "
                   f"{targets['speedup_vs_acrobot']:g}× faster than Acrobot-v1 (≤ {bound:.1f} µs)")
    bars(ax, labels, {f"env.step, {entry}": [r[entry]["median_us"] for r in single]
                      + [None] * len(unavailable) for entry in ("gym.make", "unwrapped")},
         "µs per env.step (median)")
    save_figure(fig, path)


def plot_vector(vector: Sequence[dict[str, Any]], targets: Mapping[str, float], path: Path
                ) -> None:
    """Env-steps/s and physics steps/s against num_envs (log-log), with the target line."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    rows = [{**r, "line": f"{short_name(r['env_id'])} ({r['mode']}, frame_skip "
             f"{r['frame_skip']})"} for r in vector]
    for ax, key in zip(axes, ("env_steps_per_s", "physics_steps_per_s"), strict=True):
        log_lines(ax, rows, "num_envs", key, "line", (f"{key}_q1", f"{key}_q3"),
                  dashed=lambda line: "(sync" in line)
        ax.set_xlabel("num_envs N (one core)")
        ax.set_ylabel(f"{key.replace('_', ' ')} (median; band: quartiles)")
    goal, at = targets["manipulator_physics_steps_per_s"], targets["manipulator_vector_copies"]
    axes[1].axhline(goal, color="k", ls=":", lw=1.2,
                    label=f"target: manipulator ≥ {goal:.0e} physics steps/s at N = {at}")
    axes[0].set_title("Vector env throughput: env-steps/s")
    axes[1].set_title("Vector env throughput: physics steps/s")
    for ax in axes:
        ax.legend(fontsize=7, loc="best")
    save_figure(fig, path)


def main(argv: Sequence[str] | None = None) -> None:
    """Command-line entry point."""
    args = timing.arguments(__doc__, argv, ("--cpu", {"type": int, "default": 0,
                                                      "help": "CPU to pin to (-1: none)"}))
    config = replace(QUICK if args.quick else FULL, cpu=None if args.cpu < 0 else args.cpu)
    print(run(config, args.output, args.quick))


if __name__ == "__main__":
    main()
