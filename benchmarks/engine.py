"""Engine benchmark: µs per Moreau-Jean step (single, in place, batched), shortcuts, MuJoCo.

``python -m benchmarks.engine [--output DIR] [--quick] [--models a,b]`` writes ``engine.json``
and ``engine_{batched,single_step,shortcuts}.png``: compile times, single steps from Python,
in-kernel cost per scene, batched µs per copy-step against N, each exact shortcut on vs off,
substeps per call and the brake stop, each against MuJoCo's arm where it applies.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks import engine_scenes, report, timing
from benchmarks.engine_mujoco import SCENES as MUJOCO_SCENES
from benchmarks.engine_mujoco import MujocoArm, import_mujoco
from benchmarks.engine_scenes import TIME_STEP, Copies, ModelCase, batch_arrays, calibrate_substeps
from benchmarks.report import bars, log_lines, plt, save_figure, summary
from benchmarks.timing import Log, TimingPlan
from mdi_envs.mechanics.compiled import compile_equations
from mdi_envs.stepping import MoreauJeanStepper, StepShortcuts

MODEL_TITLES = {"ball": "bouncing ball", "block": "sliding block",
                "manipulator": "blockable manipulator", "diff_drive": "diff-drive robot",
                "mujoco": "MuJoCo arm (rollout, 1 thread)"}


@dataclass(frozen=True)
class ShortcutCase:
    """One shortcut measurement: a scene timed with the shortcut on and off."""

    shortcut: str
    model: str
    scene: str
    off: StepShortcuts | str


OFF = {"skip_frictionless_rows": StepShortcuts(skip_frictionless_rows=False),
       "reuse_constant_mass": StepShortcuts(reuse_constant_mass=False),
       "direct_solve_max_size": StepShortcuts(direct_solve_max_size=0)}
SHORTCUT_CASES = tuple(ShortcutCase(name, model, scene, OFF[name]) for name, model, scene in (
    ("skip_frictionless_rows", "ball", "resting"), ("skip_frictionless_rows", "ball", "bouncing"),
    ("reuse_constant_mass", "ball", "resting"), ("reuse_constant_mass", "ball", "in flight"),
    ("reuse_constant_mass", "block", "sticking"), ("reuse_constant_mass", "block", "sliding"),
    ("reuse_constant_mass", "diff_drive", "rolling"),
    ("reuse_constant_mass", "diff_drive", "slipping"),
    ("direct_solve_max_size", "ball", "resting"), ("direct_solve_max_size", "block", "sticking"),
    ("direct_solve_max_size", "block", "sliding"),
    ("direct_solve_max_size", "manipulator", "tresca"))) + (
    ShortcutCase("no_solve", "ball", "in flight", "resting"),
    ShortcutCase("no_solve", "manipulator", "released", "engaged"))
"""Each exact shortcut off on a scene; ``no_solve``: a free scene against one that solves."""


@dataclass(frozen=True)
class EngineConfig:
    """Models, grid and timing budgets of one run."""

    models: tuple[str, ...]
    copies: tuple[int, ...]
    call_s: float
    single_plan: TimingPlan
    batch_plan: TimingPlan
    shortcut_plan: TimingPlan
    scene_copies: int
    shortcut_cases: tuple[ShortcutCase, ...]
    scene_min_substeps: int = 10
    substep_grid: tuple[int, ...] = ()
    substep_plan: TimingPlan = TimingPlan(budget_s=0.1, min_rounds=5, max_rounds=30,
                                          min_batch_s=2e-3)


FULL = EngineConfig(
    models=("ball", "block", "manipulator", "diff_drive"), copies=(1, 4, 16, 64, 256, 1024, 4096),
    call_s=0.01, single_plan=TimingPlan(budget_s=0.2, min_rounds=9, max_rounds=150,
                                        min_batch_s=2e-3),
    batch_plan=TimingPlan(budget_s=0.3, min_rounds=9, max_rounds=31),
    shortcut_plan=TimingPlan(budget_s=0.6, min_rounds=15, max_rounds=61), scene_copies=256,
    shortcut_cases=SHORTCUT_CASES, substep_grid=(1, 10, 100))
QUICK = EngineConfig(
    models=("manipulator",), copies=(1, 64, 4096), call_s=0.002,
    single_plan=TimingPlan(budget_s=0.01, min_rounds=3, max_rounds=10, min_batch_s=5e-4),
    batch_plan=TimingPlan(budget_s=0.01, min_rounds=3, max_rounds=5),
    shortcut_plan=TimingPlan(budget_s=0.01, min_rounds=3, max_rounds=5), scene_copies=64,
    shortcut_cases=SHORTCUT_CASES[-1:])
TARGETS_US = {"manipulator_batched": 0.1, "manipulator_python": 1.0, "diff_drive": 2.0}


def compile_stepper(case: ModelCase, log: Log, records: list[dict[str, Any]],
                    shortcuts: StepShortcuts | None = None) -> MoreauJeanStepper:
    """Build a stepper; append the times of its first ``step`` and ``step_batch`` to ``records``.

    These first calls compile (or load) the kernels; ``step`` is timed for the default only.
    """
    default, shortcuts = shortcuts is None, shortcuts or StepShortcuts()
    label = ", ".join(f"{k}={v}" for k, v in shortcuts._asdict().items()
                      if getattr(StepShortcuts(), k) != v) or "default shortcuts"
    log(f"compiling {case.label} ({label}) ...")
    st = MoreauJeanStepper(case.model, time_step=TIME_STEP, shortcuts=shortcuts)
    arrays = case.scenes[0].arrays()
    step_s = timing.timed_call(lambda: st.step(*arrays))[1] if default else None
    batch_s = timing.timed_call(lambda: Copies(st, *batch_arrays(case, 2), warm_start=True)())[1]
    records.append({"stepper": f"{case.label} ({label})", "step_s": step_s,
                    "step_batch_s": batch_s})
    log(f"  first step_batch {batch_s:.1f} s"
        + ("" if step_s is None else f", first step {step_s:.1f} s"))
    return st


IN_PLACE_STEPS_PER_CALL = 200
"""``InPlaceStepper.step`` calls per timed call (then the state goes back to the scene's)."""


def _in_place_call(st: MoreauJeanStepper, arrays: tuple) -> Callable[[], Any]:
    """``InPlaceStepper.step()`` in a Python loop (``IN_PLACE_STEPS_PER_CALL``), then a reset."""
    q, u, tau, brake = arrays
    stepper = st.in_place(q, u)
    stepper.tau[:] = tau
    if brake is not None:
        stepper.brake_bound[:] = brake
    step = stepper.step
    steps = range(IN_PLACE_STEPS_PER_CALL)

    def call() -> None:
        for _ in steps:
            step()
        stepper.q[:] = q
        stepper.u[:] = u

    call()  # the first calls (compile or load) before the timing's own warm-up call
    return call


def single_step_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                      arm: MujocoArm | None, config: EngineConfig, log: Log
                      ) -> list[dict[str, Any]]:
    """Per scene: ``step`` and ``InPlaceStepper.step`` from Python, and MuJoCo's ``mj_step``."""
    calls: dict[str, Callable[[], Any]] = {}
    for case in cases:
        st = steppers[case.label]
        for scene in case.scenes:
            arrays = scene.arrays()
            calls[f"{case.label}|{scene.name}|step"] = lambda st=st, a=arrays: st.step(*a)
            calls[f"{case.label}|{scene.name}|in_place"] = _in_place_call(st, arrays)
    for scene, call in (arm.single_step_calls() if arm is not None else {}).items():
        calls[f"mujoco|{scene}|mj_step"] = call
    log(f"single step: {len(calls)} callables, interleaved ...")
    timed = timing.time_interleaved(calls, config.single_plan)
    return [{**dict(zip(("model", "scene", "entry"), key.split("|"), strict=True)),
             **value.summary(IN_PLACE_STEPS_PER_CALL if key.endswith("|in_place") else 1)}
            for key, value in timed.items()]


def _batched_entry(st: MoreauJeanStepper, initial: tuple, target_s: float,
                   min_substeps: int = 1) -> tuple[Copies, int]:
    """A warm-started ``Copies`` call of about ``target_s``+, and its (>= min_substeps) substeps."""
    substeps = calibrate_substeps(lambda k: Copies(st, *initial, k, warm_start=True), target_s)
    call = Copies(st, *initial, max(min_substeps, substeps), warm_start=True)
    return call, call.num_substeps


def _mujoco_entry(arm: MujocoArm, num_copies: int, target_s: float,
                  scenes: tuple[str, ...] = MUJOCO_SCENES) -> tuple[Callable[[], Any], int]:
    """A MuJoCo rollout call of about ``target_s`` and its number of steps."""
    steps = calibrate_substeps(lambda k: arm.rollout_call(num_copies, k, scenes), target_s,
                               max_substeps=10**6)
    return arm.rollout_call(num_copies, steps, scenes), steps


def _per_copy_step(call: dict[str, Any], num_copies: int, substeps: int) -> dict[str, Any]:
    """A ``Timed.summary`` of one call, and its times scaled to one copy-step."""
    scale = 1.0 / (num_copies * substeps)
    return {"copies": num_copies, "substeps": substeps, "call": call,
            **{f"per_copy_step{k}_s": call[f"{stat}_s"] * scale
               for k, stat in (("", "median"), ("_q1", "q1"), ("_q3", "q3"), ("_min", "min"))}}


def _per_copy_rows(entries: dict[str, tuple[Callable[[], Any], int]], n: int,
                   plan: TimingPlan, fields: tuple[str, ...]) -> list[dict[str, Any]]:
    """Time the (call, substeps) entries interleaved; a row each, timed per copy-step."""
    timed = timing.time_interleaved({key: call for key, (call, _) in entries.items()}, plan)
    return [{**dict(zip(fields, key.split("|"), strict=False)),
             **_per_copy_step(value.summary(), n, entries[key][1])}
            for key, value in timed.items()]


def scene_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                arm: MujocoArm | None, config: EngineConfig, log: Log
                ) -> list[dict[str, Any]]:
    """In-kernel µs per step of each scene: ``step_batch`` with every copy in that scene."""
    n = config.scene_copies
    entries = {f"{case.label}|{scene.name}": _batched_entry(
        steppers[case.label], batch_arrays(case, n, [scene]), config.call_s,
        config.scene_min_substeps) for case in cases for scene in case.scenes}
    for scene in MUJOCO_SCENES if arm is not None else ():
        entries[f"mujoco|{scene}"] = _mujoco_entry(arm, n, config.call_s, (scene,))
    log(f"in-kernel per scene (N = {n}): {len(entries)} callables, interleaved ...")
    return _per_copy_rows(entries, n, config.batch_plan, ("model", "scene"))


def batched_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                  arm: MujocoArm | None, config: EngineConfig, log: Log
                  ) -> list[dict[str, Any]]:
    """µs per copy-step of each model's mix (and MuJoCo's) for every N, interleaved per N."""
    rows = []
    for n in config.copies:
        entries = {case.label: _batched_entry(steppers[case.label], batch_arrays(case, n),
                                              config.call_s) for case in cases}
        if arm is not None:
            entries["mujoco"] = _mujoco_entry(arm, n, config.call_s)
        measured = _per_copy_rows(entries, n, config.batch_plan, ("model",))
        rows += measured
        log(f"batched N = {n}: " + ", ".join(
            f"{r['model']} {r['per_copy_step_s'] * 1e6:.3g} µs (x{r['substeps']})"
            for r in measured) + f"; load {timing.load_text()}")
    return rows


def substeps_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                   arm: MujocoArm | None, config: EngineConfig, log: Log) -> list[dict[str, Any]]:
    """µs per copy-step of each model's mix at N = ``scene_copies`` for a few substeps per call."""
    if not config.substep_grid:
        return []
    n = config.scene_copies
    entries = {f"{case.label}|{k}": (Copies(steppers[case.label], *batch_arrays(case, n), k,
                                            warm_start=True), k)
               for case in cases for k in config.substep_grid}
    log(f"substeps per call (N = {n}): {len(entries)} callables, interleaved ...")
    return _per_copy_rows(entries, n, config.substep_plan, ("model",))


def shortcut_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                   arm: MujocoArm | None, config: EngineConfig, log: Log,
                   compile_records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Each shortcut on vs off on the same scene, batched, interleaved pair by pair."""
    by_label = {c.label: c for c in cases}
    variants: dict[tuple[str, StepShortcuts], MoreauJeanStepper] = {}
    n = config.scene_copies
    rows = []
    for sc in config.shortcut_cases:
        case = by_label.get(sc.model)
        if case is None:
            continue
        on_arrays = batch_arrays(case, n, [case.scene(sc.scene)])
        on, _ = _batched_entry(steppers[case.label], on_arrays, config.call_s,
                               config.scene_min_substeps)
        difference: float | None = None
        if isinstance(sc.off, StepShortcuts):
            key = (case.label, sc.off)
            if key not in variants:
                variants[key] = compile_stepper(case, log, compile_records, sc.off)
            off = Copies(variants[key], *on_arrays, on.num_substeps, warm_start=True)
            on()  # both from the same initial states: the largest |state difference|
            off()
            difference = float(max(np.abs(on.q - off.q).max(), np.abs(on.u - off.u).max()))
        else:
            off, _ = _batched_entry(steppers[case.label],
                                    batch_arrays(case, n, [case.scene(sc.off)]), config.call_s,
                                    config.scene_min_substeps)
        timed = timing.time_interleaved({"on": on, "off": off}, config.shortcut_plan)
        row = {"shortcut": sc.shortcut, "model": sc.model, "scene": sc.scene,
               "off_scene": sc.off if isinstance(sc.off, str) else sc.scene,
               "off_shortcuts": sc.off._asdict() if isinstance(sc.off, StepShortcuts) else None,
               "on": _per_copy_step(timed["on"].summary(), n, on.num_substeps),
               "off": _per_copy_step(timed["off"].summary(), n, off.num_substeps),
               "max_state_difference": difference}
        row["speedup"] = row["off"]["per_copy_step_s"] / row["on"]["per_copy_step_s"]
        row["speedup_fastest_rounds"] = (row["off"]["per_copy_step_min_s"]
                                         / row["on"]["per_copy_step_min_s"])
        rows.append(row)
        log(f"shortcut {sc.shortcut} on {sc.model}/{sc.scene}: speedup {row['speedup']:.2f}")
    return rows


def brake_stop_study(cases: list[ModelCase], steppers: dict[str, MoreauJeanStepper],
                     arm: MujocoArm | None, config: EngineConfig, log: Log) -> dict[str, Any]:
    """Steps to stop a 1 rad/s relative motion after the brake engages: ours and MuJoCo's."""
    result: dict[str, Any] = {}
    st = steppers.get("manipulator")
    if st is not None:
        q, u, trace, steps = np.zeros(2), np.array([0.0, 1.0]), [1.0], None
        while steps is None and len(trace) <= 100:  # at most 100 steps
            out = st.step(q, u, np.zeros(1), np.array([np.inf]))
            q, u = out.q, out.u
            trace.append(abs(float(u[1] - u[0])))
            steps = len(trace) - 1 if trace[-1] < 0.01 else None
        result["ours"] = {"steps": steps, "relative_speed_after_first_step": trace[1],
                          "relative_angle_at_stop": float(q[1] - q[0]),
                          "relative_speed_trace": trace}
    if arm is not None:
        result["mujoco_default"] = arm.brake_stop(None)
        result["mujoco_stiffest"] = arm.brake_stop((2 * TIME_STEP, 1.0))
    log("brake stop (steps to |relative velocity| < 1 %): " + ", ".join(
        f"{k} {v['steps']}" for k, v in result.items()))
    return result


def evaluate_targets(single: list[dict], batched: list[dict]) -> list[dict[str, Any]]:
    """The speed targets against the measurements (None where the model was not run)."""
    targets = []
    for model, title, batched_key, python_key in (
            ("manipulator", "manipulator", "manipulator_batched", "manipulator_python"),
            ("diff_drive", "diff-drive", "diff_drive", "diff_drive")):
        rows = [r for r in batched if r["model"] == model]
        largest = max(rows, key=lambda r: r["copies"], default=None)
        targets.append(report.target_row(
            f"{title}, batched, µs per copy-step (mix, largest N)", "≤", TARGETS_US[batched_key],
            "µs", None if largest is None else largest["per_copy_step_s"] * 1e6,
            "" if largest is None else f"N = {largest['copies']}; best over N "
            f"{min(r['per_copy_step_s'] for r in rows) * 1e6:.3g} µs"))
        python = [r["median_s"] for r in single if r["model"] == model and r["entry"] == "in_place"]
        targets.append(report.target_row(
            f"{title}, one InPlaceStepper.step() from Python (slowest scene)", "≤",
            TARGETS_US[python_key], "µs", max(python) * 1e6 if python else None))
    return targets


def run(config: EngineConfig, output: Path, quick: bool) -> str:
    """Run the whole benchmark, write the outputs and return its summary (Markdown)."""
    settings = {"quick": quick, "time_step": TIME_STEP,
                **{k: v for k, v in asdict(config).items() if k != "shortcut_cases"}}
    packages = (*timing.VERSIONED_PACKAGES, "mujoco")
    with report.study("engine", output, settings, packages, speed=True) as (record, log, clock):
        record["notes"] = []
        cases = engine_scenes.model_cases(config.models)
        mujoco, mujoco_note = import_mujoco()
        arm = MujocoArm(mujoco) if mujoco is not None else None
        if mujoco_note:
            record["notes"].append(mujoco_note)
            log(mujoco_note)
        timing.checkpoint(record, "compile", clock)
        record["compile"] = []
        steppers = {case.label: compile_stepper(case, log, record["compile"]) for case in cases}
        record["models"] = [{"label": c.label, "model": c.model.__name__,
                             "mix": [s.name for s in c.mix_scenes],
                             "scenes": report.json_safe([asdict(s) for s in c.scenes])}
                            for c in cases]
        if arm is not None and "manipulator" in steppers:
            st, ours = steppers["manipulator"], np.empty((2, 2))
            compile_equations(st.model).mass(np.array(engine_scenes.MANIPULATOR_Q), st._values,
                                             ours)
            record["mujoco_mass_matrix_difference"] = arm.mass_matrix_check(ours)
        studies = {"single_step": single_step_study, "per_scene": scene_study,
                   "batched": batched_study, "substeps": substeps_study,
                   "shortcuts": partial(shortcut_study, compile_records=record["compile"]),
                   "brake_stop": brake_stop_study}
        for key, study in studies.items():
            timing.checkpoint(record, key.replace("_", " "), clock)
            record[key] = study(cases, steppers, arm, config, log)
        if arm is not None:
            arm.close()
        timing.checkpoint(record, "end", clock)
        record["targets"] = evaluate_targets(record["single_step"], record["batched"])
        plot_batched(record["batched"], record["substeps"], output / "engine_batched.png")
        plot_single_step(record["single_step"], record["per_scene"],
                         output / "engine_single_step.png")
        plot_shortcuts(record["shortcuts"], output / "engine_shortcuts.png")
    return summary(record, ("numpy", "numba", "mujoco"))


def plot_batched(batched: Sequence[dict[str, Any]], substeps: Sequence[dict[str, Any]],
                 path: Path) -> None:
    """µs per copy-step against N (and against substeps per call), one line per model."""
    panels = 2 if substeps else 1
    fig, axes = plt.subplots(1, panels, figsize=(7.5 + 4.5 * (panels - 1), 4.8), sharey=True,
                             gridspec_kw={"width_ratios": [5, 3][:panels]})
    axes = list(np.atleast_1d(axes))
    for ax, rows, x in zip(axes, (batched, substeps), ("copies", "substeps"), strict=False):
        log_lines(ax, rows, x, "per_copy_step_s", "model", ("per_copy_step_q1_s",
                  "per_copy_step_q3_s"), 1e6, lambda m: MODEL_TITLES.get(m, m),
                  lambda m: m == "mujoco")
        ax.set_xlabel(f"{x} per step_batch call")
    for model, key, color in (("manipulator", "manipulator_batched", "tab:green"),
                              ("diff_drive", "diff_drive", "tab:red")):
        if any(r["model"] == model for r in batched):
            axes[0].axhline(TARGETS_US[key], color=color, lw=0.9, ls=":",
                            label=f"{model} target {TARGETS_US[key]:g} µs")
    axes[0].set_title("Batched stepping (single thread), per copy-step")
    axes[0].set_ylabel("µs per copy-step (band: quartiles)")
    axes[0].legend(fontsize=7, loc="best")
    save_figure(fig, path)


def plot_single_step(single: Sequence[dict[str, Any]], scenes: Sequence[dict[str, Any]],
                     path: Path) -> None:
    """Horizontal bars per (model, scene): Python step, in-place step, in-kernel step [µs]."""
    index = {(r["model"], r["scene"], r["entry"]): r["median_s"] * 1e6 for r in single}
    index.update({(r["model"], r["scene"], "kernel"): r["per_copy_step_s"] * 1e6 for r in scenes})
    keys = list(dict.fromkeys((r["model"], r["scene"]) for r in single))
    fig, ax = plt.subplots(figsize=(8.5, 0.42 * len(keys) + 1.6))
    ax.axvline(TARGETS_US["manipulator_python"], color="tab:green", lw=0.9, ls=":",
               label=f"manipulator target (Python) {TARGETS_US['manipulator_python']:g} µs")
    bars(ax, [f"{m} / {s}" for m, s in keys], {
        "one step from Python: step() / mj_step": [
            index.get((m, s, "mj_step" if m == "mujoco" else "step")) for m, s in keys],
        "InPlaceStepper.step() from Python": [index.get((m, s, "in_place")) for m, s in keys],
        "in-kernel (batched)": [index.get((m, s, "kernel")) for m, s in keys]}, "µs per step")
    save_figure(fig, path)


def plot_shortcuts(shortcuts: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the speedup off/on per shortcut (labels: on vs off µs per copy-step)."""
    fig, ax = plt.subplots(figsize=(8.5, 0.4 * max(len(shortcuts), 1) + 1.6))
    ax.axvline(1.0, color="k", lw=0.8)
    labels = [f"{'no solve (free vs active)' if r['shortcut'] == 'no_solve' else r['shortcut']}: "
              f"{r['model']} / {r['scene']}" + ("" if r["off_scene"] == r["scene"]
                                                else f" vs {r['off_scene']}") + " ("
              f"{r['on']['per_copy_step_s'] * 1e6:.3g} vs "
              f"{r['off']['per_copy_step_s'] * 1e6:.3g} µs)" for r in shortcuts]
    bars(ax, labels, {"ratio of medians": [r["speedup"] for r in shortcuts],
                      "ratio of fastest rounds": [r["speedup_fastest_rounds"] for r in shortcuts]},
         "time off / time on (> 1: the shortcut saves time)")
    save_figure(fig, path)


def main(argv: Sequence[str] | None = None) -> None:
    """Command-line entry point."""
    args = timing.arguments(__doc__, argv, ("--models", {"help": "comma-separated, of "
                                                         + ", ".join(FULL.models)}))
    config = QUICK if args.quick else FULL
    if args.models:
        models = tuple(args.models.split(","))
        unknown = [model for model in models if model not in FULL.models]
        if unknown:
            raise SystemExit(f"--models: unknown {unknown}; choose from {FULL.models}")
        config = replace(config, models=models)
    print(run(config, args.output, args.quick))


if __name__ == "__main__":
    main()
