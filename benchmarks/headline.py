"""The suite's headline table: every benchmark's target checks and the stress verdicts, in one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from benchmarks.report import markdown_table, target_row

SOURCES = (("engine", "engine.json"), ("envs", "envs.json"),
           ("precision", "work_precision.json"), ("stress", "stress.json"),
           ("startup", "startup.json"), ("control", "control.json"))  # fmt: skip
"""(benchmark name, result file) whose targets enter the table, in this order."""


def stress_row(record: dict[str, Any]) -> dict[str, Any]:
    """One row summarizing the stress cases: passed of total, failures named."""
    cases = record.get("cases") or []
    failed = [case["name"] for case in cases if not case.get("passed")]
    return target_row("every stress case passes its criteria", "=", len(cases), "cases",
                      len(cases) - len(failed), ("failed: " + ", ".join(failed)) if failed else "",
                      met=bool(cases) and not failed)


def engine_peer_rows(record: dict[str, Any]) -> list[dict[str, Any]]:
    """Ours against MuJoCo's arm in the engine run."""
    rows = []
    largest: dict[str, dict[str, Any]] = {}
    for entry in record.get("batched") or []:
        if entry["copies"] >= largest.get(entry["model"], {}).get("copies", 0):
            largest[entry["model"]] = entry
    if "manipulator" in largest and "mujoco" in largest:
        ours, peer = largest["manipulator"]["per_copy_step_s"], largest["mujoco"]["per_copy_step_s"]
        rows.append(target_row(
            "manipulator step vs MuJoCo arm (rollout), batched N = "
            f"{largest['manipulator']['copies']}: MuJoCo time / ours", "", None, "×", peer / ours,
            f"ours {ours * 1e6:.3g} µs, MuJoCo {peer * 1e6:.3g} µs per copy-step", peer > ours))
    stop = record.get("brake_stop") or {}
    if "ours" in stop and "mujoco_default" in stop:
        rows.append(target_row(
            "brake stops relative motion (< 1 %) within one step", "≤", 1, "steps",
            stop["ours"]["steps"], "MuJoCo eq_active, default solref: "
            f"{stop['mujoco_default']['steps']} steps", stop["ours"]["steps"] <= 1))
    return rows


def _number(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.3g}"
    return "-" if value is None else str(value)


def write_headline(folder: Path) -> str:
    """Write ``headline.json`` and ``headline.md`` from the results in ``folder``."""
    folder = Path(folder)
    rows: list[dict[str, Any]] = []
    runs = {}
    for name, filename in SOURCES:
        if not (folder / filename).exists():
            continue
        record = json.loads((folder / filename).read_text())
        runs[name] = {"file": filename, "machine": record.get("machine"),
                      "run_time_s": record.get("run_time_s"), "quick": record.get("quick")}
        extra = {"engine": engine_peer_rows, "stress": lambda r: [stress_row(r)]}.get(name)
        rows += [{"benchmark": name, **target, "met": bool(target.get("met"))}
                 for target in (record.get("targets") or []) + (extra(record) if extra else [])]
    (folder / "headline.json").write_text(json.dumps({"runs": runs, "rows": rows}, indent=1,
                                                     default=str) + "\n")  # fmt: skip
    text = markdown_table(
        [[r["benchmark"], r["target"], f"{_number(r['measured'])} {r['unit']}".strip(),
          "(comparison)" if r["threshold"] is None
          else f"{r['comparison']} {_number(r['threshold'])} {r['unit']}".strip(),
          "yes" if r["met"] else "**no**", r["note"]] for r in rows],
        ["benchmark", "target", "measured", "target value", "met", "note"],
    ) if rows else f"no benchmark results with targets in {folder}"  # fmt: skip
    (folder / "headline.md").write_text(text + "\n")
    return text
