"""The suite's headline table: every benchmark's target checks and the stress verdicts, in one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from benchmarks.report import markdown_table

SOURCES = (("engine", "engine.json"), ("envs", "envs.json"),
           ("precision", "work_precision.json"), ("stress", "stress.json"),
           ("startup", "startup.json"), ("control", "control.json"))  # fmt: skip
"""(benchmark name, result file) whose targets enter the table, in this order."""


def target_rows(name: str, record: dict[str, Any]) -> list[dict[str, Any]]:
    """The ``targets`` of one record (``benchmarks.report.target_row``), with the benchmark."""
    return [{"benchmark": name, **target, "met": bool(target.get("met"))}
            for target in record.get("targets") or []]


def stress_row(record: dict[str, Any]) -> dict[str, Any]:
    """One row summarizing the stress cases: passed of total, failures named."""
    cases = record.get("cases") or []
    failed = [case["name"] for case in cases if not case.get("passed")]
    return {"benchmark": "stress", "target": "every stress case passes its criteria",
            "measured": len(cases) - len(failed), "threshold": len(cases),
            "unit": "cases", "comparison": "=", "met": bool(cases) and not failed,
            "note": ("failed: " + ", ".join(failed)) if failed else ""}  # fmt: skip


def engine_peer_rows(record: dict[str, Any]) -> list[dict[str, Any]]:
    """Ours against MuJoCo's arm in the engine run."""
    rows = []
    largest: dict[str, dict[str, Any]] = {}
    for entry in record.get("batched") or []:
        if entry["model"] in ("manipulator", "mujoco"):
            if entry["copies"] >= largest.get(entry["model"], {}).get("copies", 0):
                largest[entry["model"]] = entry
    if len(largest) == 2:
        ours, peer = largest["manipulator"], largest["mujoco"]
        rows.append({
            "benchmark": "engine", "target": "manipulator step vs MuJoCo arm (rollout), "
            f"batched N = {ours['copies']}: MuJoCo time / ours",
            "measured": peer["per_copy_step_s"] / ours["per_copy_step_s"], "threshold": None,
            "unit": "×", "comparison": "", "met": peer["per_copy_step_s"] > ours["per_copy_step_s"],
            "note": f"ours {ours['per_copy_step_s'] * 1e6:.3g} µs, MuJoCo "
                    f"{peer['per_copy_step_s'] * 1e6:.3g} µs per copy-step",
        })  # fmt: skip
    stop = record.get("brake_stop") or {}
    if "ours" in stop and "mujoco_default" in stop:
        ours_steps, peer_steps = stop["ours"]["steps"], stop["mujoco_default"]["steps"]
        rows.append({
            "benchmark": "engine", "target": "brake stops relative motion (< 1 %) within one step",
            "measured": ours_steps, "threshold": 1, "unit": "steps", "comparison": "≤",
            "met": ours_steps <= 1,
            "note": f"MuJoCo eq_active, default solref: {peer_steps} steps",
        })  # fmt: skip
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
        path = folder / filename
        if not path.exists():
            continue
        record = json.loads(path.read_text())
        runs[name] = {"file": filename, "machine": record.get("machine"),
                      "run_time_s": record.get("run_time_s"), "quick": record.get("quick")}
        rows.extend(target_rows(name, record))
        if name == "engine":
            rows.extend(engine_peer_rows(record))
        if name == "stress":
            rows.append(stress_row(record))
    (folder / "headline.json").write_text(json.dumps({"runs": runs, "rows": rows}, indent=1,
                                                     default=str) + "\n")  # fmt: skip
    if not rows:
        text = f"no benchmark results with targets in {folder}"
    else:
        text = markdown_table(
            [[r["benchmark"], r["target"], f"{_number(r['measured'])} {r['unit']}".strip(),
              "(comparison)" if r["threshold"] is None
              else f"{r['comparison']} {_number(r['threshold'])} {r['unit']}".strip(),
              "yes" if r["met"] else "**no**", r["note"]] for r in rows],
            ["benchmark", "target", "measured", "target value", "met", "note"],
        )  # fmt: skip
    (folder / "headline.md").write_text(text + "\n")
    return text


__all__ = ["SOURCES", "engine_peer_rows", "stress_row", "target_rows", "write_headline"]
