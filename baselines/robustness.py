"""Robustness of every controller: start perturbations and a model the controller does not know.

For (env id, objective) each controller -- the optimal reference open loop, optionally the MPC
(``baselines.model_based``), and every trained seed of every algorithm (``baselines/trained``)
-- is played from ``num_seeds`` perturbed starts under each condition:

* start perturbation scale s in ``SCALES`` (the env's ``reset_noise_scale``: uniform in
  [-s, s] rad, rad/s, m, m/s; the envs' default is 0.01);
* model mismatch at the default scale, in the env only (the controllers keep the nominal
  model): ``MISMATCHES`` -- link masses +-10 % (manipulator), chassis mass +-10 % and the
  friction coefficients +-20 % (robot). Neither mission env has a restitution coefficient
  (the brake and the wheels have no impacts), so no restitution row.

Reported per controller and condition: the success rate (mean over a trained algorithm's seeds,
with the per-seed rates) and, over the successes, the time and effort ratios to the reference.
``python -m baselines.robustness ENV_ID|all [--objective T] [--seeds N] [--mpc]`` writes
``robustness_ENV_TASK.json``, ``.png`` (success against the perturbation scale, one curve per
controller; success under each mismatch) and ``robustness.md`` (the table of every
``robustness_*.json`` in the output folder). ``--controllers LABEL ... [--scales ...]
[--no-mismatch | --mismatches LABEL ...]`` plays only those and merges their results into the
study in the folder (``merge_studies``), so a slow controller's conditions can be run one at a
time (``--scales`` with no value plays no perturbation scale). Every finished episode is
appended to ``episodes.jsonl`` in the output folder; ``--resume`` plays only the episodes not
in it, so a long run (the MPC under a mismatch: minutes per episode) can stop and go on later.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from baselines.compare import (
    REFERENCE_NAMES,
    TRAINED_DIR,
    Controller,
    group_by_algorithm,
    load_policy,
    play,
    reference_effort,
    registered_controllers,
    require_known_labels,
    shipped_algorithms,
    shipped_policies,
    summarize,
)
from baselines.hyperparameters import ALGORITHMS
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulatorParameters
from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters
from optimal.references import load_reference

SCALES = (0.01, 0.03, 0.1, 0.3)
"""Start perturbation half-widths [rad, rad/s, m, m/s]."""

DEFAULT_SCALE = 0.01
"""The envs' ``reset_noise_scale``, used with the mismatches."""

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"


def _manipulator(factor: float) -> BlockableManipulatorParameters:
    nominal = BlockableManipulatorParameters()
    return dataclasses.replace(nominal, link1_mass=factor * nominal.link1_mass,
                               link2_mass=factor * nominal.link2_mass)


def _robot(mass: float = 1.0, friction: float = 1.0) -> DiffDriveParameters:
    nominal = DiffDriveParameters()
    return dataclasses.replace(nominal, mass=mass * nominal.mass,
                               wheel_friction=friction * nominal.wheel_friction,
                               stick_friction=friction * nominal.stick_friction)


MISMATCHES: dict[str, tuple[tuple[str, Callable[[], Any]], ...]] = {
    MANIPULATOR: (("link masses +10 %", lambda: _manipulator(1.1)),
                  ("link masses -10 %", lambda: _manipulator(0.9))),
    DIFF_DRIVE: (("mass +10 %", lambda: _robot(mass=1.1)),
                 ("mass -10 %", lambda: _robot(mass=0.9)),
                 ("friction +20 %", lambda: _robot(friction=1.2)),
                 ("friction -20 %", lambda: _robot(friction=0.8))),
}
"""Env id -> (label, parameters factory) of the env's model mismatches."""


def controllers_for(env_id: str, objective: str, mpc: bool = False,
                    trained_dir: Path = TRAINED_DIR) -> list[tuple[str, list[Controller]]]:
    """(label, runs) per controller: untrained ones with one run, trained ones per seed."""
    rows = [(c.label, [c]) for c in registered_controllers(env_id, objective)]
    if mpc:
        from baselines.model_based import mpc_controller

        controller = mpc_controller(env_id, objective)
        if controller is None:
            raise RuntimeError("the MPC needs CasADi (pip install 'mdi-envs[optimal]')")
        rows.append((controller.label, [controller]))
    for algo, paths in group_by_algorithm(shipped_policies(env_id, objective, trained_dir)).items():
        rows.append((algo, [load_policy(path)[0] for path in paths]))
    return rows


EPISODES_FILE = "episodes.jsonl"
"""The CLI's file of finished episodes in its output folder (``--resume`` reads it)."""


@dataclasses.dataclass(frozen=True)
class EpisodeRecord:
    """One finished episode of the study, as kept in the episodes file (no trajectory).

    Attributes:
        env_id, objective: the study. controller: its label. run: index of the controller's run
            (a trained algorithm's seed). condition: the condition's label. seed: the reset
            seed.
        is_success, elapsed_time, effort, solver_failures, compute_per_step: as
            ``baselines.compare.Episode`` (elapsed_time [s], effort [N^2 m^2 s],
            compute_per_step [s]).
    """

    env_id: str
    objective: str
    controller: str
    run: int
    condition: str
    seed: int
    is_success: bool
    elapsed_time: float
    effort: float
    solver_failures: int
    compute_per_step: float


def read_episodes(path: Path | None, env_id: str, objective: str
                  ) -> dict[tuple[str, int, str, int], EpisodeRecord]:  # fmt: skip
    """{(controller, run, condition, seed): record} of the study (env id, objective) in ``path``.

    A missing file is an empty one; a last line cut short (a run killed while writing) is
    skipped.
    """
    if path is None or not path.exists():
        return {}
    records = {}
    for line in path.read_text().splitlines():
        try:
            record = EpisodeRecord(**json.loads(line))
        except (json.JSONDecodeError, TypeError):
            continue
        if (record.env_id, record.objective) == (env_id, objective):
            records[(record.controller, record.run, record.condition, record.seed)] = record
    return records


def _append(path: Path, record: EpisodeRecord) -> None:
    """One JSON line at the end of ``path``, after a newline if its last line was cut short."""
    with path.open("a+b") as stream:
        if stream.seek(0, os.SEEK_END):
            stream.seek(-1, os.SEEK_END)
            if stream.read(1) != b"\n":
                stream.write(b"\n")
        stream.write(json.dumps(dataclasses.asdict(record)).encode() + b"\n")


def robustness(env_id: str, objective: str, num_seeds: int = 20, mpc: bool = False,
               scales: Sequence[float] = SCALES, trained_dir: Path = TRAINED_DIR,
               log: Callable[[str], None] | None = None,
               mismatches: bool | Sequence[str] = True,
               only: Sequence[str] | None = None, show_bar: bool = False,
               episodes_path: Path | None = None, resume: bool = False) -> dict[str, Any]:
    """Play every controller under every condition (see the module docstring).

    ``mismatches=False`` plays the perturbation scales only, a sequence of labels (of
    ``MISMATCHES[env_id]``) only those mismatches; ``only`` names the controllers to play
    (labels, e.g. "PPO"; None: all), for a study completed piece by piece (``merge_studies``).
    ``show_bar``: a tqdm bar over the episodes on stderr. ``episodes_path``: a JSON-lines file
    to which each finished episode is appended (``EpisodeRecord``); with ``resume`` the
    episodes already in it are not played again, so an interrupted study goes on where it
    stopped.

    Returns:
        {"env_id", "objective", "reference", "optimal_time" [s], "optimal_effort", "seeds",
        "conditions": [{"label", "scale", "mismatch"}], "controllers": [{"label", "runs",
        "results": [{"condition", "success_rate" (mean over runs), "run_success_rates",
        "time_ratio", "effort_ratio" (means over runs with successes, None without)}]}]}.
    """
    if (env_id, objective) not in REFERENCE_NAMES:
        raise ValueError(f"no optimal reference for {env_id} objective {objective!r}")
    say = log or (lambda _: None)
    reference = load_reference(REFERENCE_NAMES[(env_id, objective)])
    optimal_time, optimal_effort = reference.final_time, reference_effort(reference)
    conditions = [{"label": f"perturbation {scale:g}", "scale": float(scale), "mismatch": None}
                  for scale in scales]
    factories = dict(MISMATCHES[env_id])
    if isinstance(mismatches, bool):
        mismatch_labels = list(factories) if mismatches else []
    else:
        mismatch_labels = list(mismatches)
        unknown = [label for label in mismatch_labels if label not in factories]
        if unknown:
            raise ValueError(f"unknown mismatch {unknown} for {env_id}; known: {list(factories)}")
    conditions += [{"label": label, "scale": DEFAULT_SCALE, "mismatch": label}
                   for label in factories if label in mismatch_labels]
    available = controllers_for(env_id, objective, mpc, trained_dir)
    require_known_labels(only, [label for label, _ in available], env_id, objective)
    playing = [(label, runs) for label, runs in available if only is None or label in only]
    bar = tqdm(total=num_seeds * len(conditions) * sum(len(runs) for _, runs in playing),
               desc=f"{env_id.split('/')[-1]} {objective}", unit="episode", mininterval=10.0,
               disable=not show_bar)
    finished = read_episodes(episodes_path, env_id, objective) if resume else {}
    rows = []
    for label, runs in playing:
        results = []
        for condition in conditions:
            summaries = []
            for run, controller in enumerate(runs):
                kwargs: dict[str, Any] = {**controller.env_kwargs,
                                          "reset_noise_scale": condition["scale"]}
                if condition["mismatch"] is not None:
                    kwargs["parameters"] = factories[str(condition["mismatch"])]()
                episodes = []
                for seed in range(num_seeds):
                    key = (label, run, str(condition["label"]), seed)
                    record = finished.get(key)
                    if record is None:
                        episode = play(env_id, controller.make_policy, seed, True, **kwargs)
                        record = EpisodeRecord(
                            env_id, objective, *key, episode.is_success, episode.elapsed_time,
                            episode.effort, episode.solver_failures, episode.compute_per_step)
                        if episodes_path is not None:
                            _append(episodes_path, record)
                    episodes.append(record)
                    bar.update()
                summaries.append(summarize(episodes, optimal_time, optimal_effort))
            rates = [s["success_rate"] for s in summaries]
            result = {"condition": condition["label"], "success_rate": float(np.mean(rates)),
                      "run_success_rates": rates}
            for ratio in ("time_ratio", "effort_ratio"):
                values = [s[ratio] for s in summaries if s[ratio] is not None]
                result[ratio] = float(np.mean(values)) if values else None
            results.append(result)
            say(f"{env_id} {objective} {label} [{condition['label']}]: success "
                f"{result['success_rate']:.0%} over {len(runs)} run(s) x {num_seeds} starts")
        rows.append({"label": label, "runs": len(runs), "results": results})
    bar.close()
    return {"env_id": env_id, "objective": objective, "reference": reference.name,
            "optimal_time": optimal_time, "optimal_effort": optimal_effort,
            "seeds": num_seeds, "conditions": conditions, "controllers": rows}


def merge_studies(old: dict[str, Any], new: dict[str, Any],
                  shipped: Collection[str] | None = None) -> dict[str, Any]:
    """``old`` with the (controller, condition) results of ``new`` added or replaced.

    Both must be of the same env, objective and number of starts. Conditions keep their order
    (scales ascending, then the mismatches); a controller without a result for some condition
    shows none there. With ``shipped`` (the algorithms that have trained policies now), an
    old row of another trained algorithm (``ALGORITHMS``) is dropped: its policies were
    withdrawn.
    """
    for key in ("env_id", "objective", "seeds"):
        if old[key] != new[key]:
            raise ValueError(f"cannot merge studies of different {key}: {old[key]} and "
                             f"{new[key]}")
    conditions = {c["label"]: c for c in old["conditions"] + new["conditions"]}
    mismatch_order = [label for label, _ in MISMATCHES[new["env_id"]]]
    ordered = sorted(conditions.values(), key=lambda c: (
        c["mismatch"] is not None,
        c["scale"] if c["mismatch"] is None else mismatch_order.index(c["mismatch"])))
    rows = {row["label"]: row for row in old["controllers"]
            if shipped is None or row["label"] not in ALGORITHMS or row["label"] in shipped}
    for row in new["controllers"]:
        kept = rows.get(row["label"], {"results": []})["results"]
        by_condition = {r["condition"]: r for r in kept + row["results"]}
        rows[row["label"]] = {**row, "results": [by_condition[c["label"]] for c in ordered
                                                 if c["label"] in by_condition]}
    return {**new, "conditions": ordered, "controllers": list(rows.values())}


def markdown_table(studies: Sequence[dict[str, Any]]) -> str:
    """One row per env x objective x controller; success (ratio over successes) per condition."""
    lines: list[str] = []
    for study in studies:
        labels = [c["label"] for c in study["conditions"]]
        ratio_name = "time" if study["objective"] == "time" else "effort"
        lines += [f"\n{study['env_id']} {study['objective']} ({study['seeds']} starts per run; "
                  f"success, {ratio_name}/optimal over the successes)\n",
                  "| controller | runs | " + " | ".join(labels) + " |",
                  "|---|---|" + "---|" * len(labels)]
        for row in study["controllers"]:
            cells = []
            results = {result["condition"]: result for result in row["results"]}
            for label in labels:
                if label not in results:
                    cells.append("-")
                    continue
                ratio = results[label][f"{ratio_name}_ratio"]
                cells.append(f"{results[label]['success_rate']:.0%}"
                             + ("" if ratio is None else f" ({ratio:.2f})"))
            lines.append(f"| {row['label']} | {row['runs']} | " + " | ".join(cells) + " |")
    return "\n".join(lines).strip()


def plot_robustness(study: dict[str, Any], path: Path) -> Path:
    """Success against the perturbation scale per controller, and under each mismatch.

    Each mismatch bar is labelled with its success in % ("n/a": that cell was not played).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scaled = [c for c in study["conditions"] if c["mismatch"] is None]
    mismatched = [c for c in study["conditions"] if c["mismatch"] is not None]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5))
    width = 0.8 / max(len(study["controllers"]), 1)
    for k, row in enumerate(study["controllers"]):
        success = {r["condition"]: 100 * r["success_rate"] for r in row["results"]}
        played = [c for c in scaled if c["label"] in success]
        left.plot([c["scale"] for c in played], [success[c["label"]] for c in played], "o-",
                  label=f"{row['label']} ({row['runs']} run{'s' * (row['runs'] > 1)})")
        positions = np.arange(len(mismatched)) + k * width
        heights = [success.get(c["label"], np.nan) for c in mismatched]
        right.bar(positions, heights, width, label=row["label"])
        for position, height in zip(positions, heights, strict=True):  # a 0 % bar has no height
            right.text(position, 1.0 if np.isnan(height) else height + 1.0,
                       "n/a" if np.isnan(height) else f"{height:.0f}", ha="center",
                       va="bottom", rotation=90, fontsize=6)
    left.set_xscale("log")
    left.set_xlabel("start perturbation scale [rad, rad/s, m, m/s]")
    left.set_ylabel("success [%]")
    left.set_ylim(-3, 103)
    left.set_title(f"{study['env_id'].split('/')[-1]} {study['objective']}: perturbed starts")
    left.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2)
    right.set_xticks(np.arange(len(mismatched)) + width * (len(study["controllers"]) - 1) / 2)
    right.set_xticklabels([c["label"] for c in mismatched], fontsize=8)
    right.set_ylabel("success [%]")
    right.set_ylim(0, 115)
    right.set_title(f"model mismatch (scale {DEFAULT_SCALE:g})")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m baselines.robustness ENV_ID|all [--objective T] [--seeds N] [--mpc]``."""
    parser = argparse.ArgumentParser(prog="python -m baselines.robustness",
                                     description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("env_id", choices=[MANIPULATOR, DIFF_DRIVE, "all"])
    parser.add_argument("--objective", choices=("time", "effort"), default=None)
    parser.add_argument("--seeds", type=int, default=20, help="perturbed starts per run")
    parser.add_argument("--scales", type=float, nargs="*", default=list(SCALES),
                        help="start perturbation scales (none: play no scale)")
    parser.add_argument("--mpc", action="store_true", help="include the MPC (needs CasADi)")
    parser.add_argument("--mismatch", action=argparse.BooleanOptionalAction, default=True,
                        help="also play the model mismatches (default: yes)")
    parser.add_argument("--mismatches", nargs="+", default=None, metavar="LABEL",
                        help="play only these model mismatches (labels as in the table)")
    parser.add_argument("--controllers", nargs="+", default=None, metavar="LABEL",
                        help="play only these controllers (labels as in the table) and merge "
                        "their results into the study already in --output")
    parser.add_argument("--trained", type=Path, default=TRAINED_DIR)
    parser.add_argument("--output", type=Path, default=Path("results/robustness"))
    parser.add_argument("--resume", action="store_true",
                        help="reuse the episodes already in OUTPUT/episodes.jsonl (every "
                        "finished episode is appended there): an interrupted run goes on")
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error(f"--seeds must be >= 1, got {args.seeds}")
    jobs = [key for key in REFERENCE_NAMES
            if args.env_id in ("all", key[0]) and args.objective in (None, key[1])]
    if not jobs:
        parser.error(f"{args.env_id} has no objective {args.objective!r}")
    args.output.mkdir(parents=True, exist_ok=True)
    for env_id, objective in jobs:
        study = robustness(env_id, objective, args.seeds, args.mpc, args.scales, args.trained,
                           log=lambda line: tqdm.write(line, file=sys.stderr),
                           mismatches=(args.mismatches if args.mismatch and args.mismatches
                                       else args.mismatch),
                           only=args.controllers, show_bar=True,
                           episodes_path=args.output / EPISODES_FILE, resume=args.resume)
        stem = f"robustness_{env_id.split('/')[-1]}_{objective}"
        path = args.output / f"{stem}.json"
        if args.controllers is not None and path.exists():
            study = merge_studies(json.loads(path.read_text()), study,
                                  shipped_algorithms(env_id, objective, args.trained))
        path.write_text(json.dumps(study, indent=1))
        plot_robustness(study, args.output / f"{stem}.png")
    # every study in the folder, so that rerunning one env x objective keeps the others' rows
    studies = [json.loads(path.read_text())
               for path in sorted(args.output.glob("robustness_*.json"))]
    table = markdown_table(studies)
    (args.output / "robustness.md").write_text(table + "\n")
    print(table)
    return 0


__all__ = ["DEFAULT_SCALE", "EPISODES_FILE", "MISMATCHES", "SCALES", "EpisodeRecord",
           "controllers_for", "main", "markdown_table", "read_episodes",
           "merge_studies", "plot_robustness", "robustness"]


if __name__ == "__main__":
    raise SystemExit(main())
