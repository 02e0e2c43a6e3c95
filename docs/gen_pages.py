"""Generate the environment, results and API pages of the docs site (run by mkdocs-gen-files).

* ``envs/``: one page per id registered in the ``mdi_envs/`` namespace of Gymnasium's registry,
  from the env class docstring (read statically by griffe), the registration, the shipped
  optimal references for that id and its GIF (``docs/assets/<Name>.gif``).
* ``results/``: tables (pandas ``to_markdown``) and the committed PNGs, read from the committed
  JSON of ``benchmarks/results``, ``baselines/comparison``, ``baselines/robustness``,
  ``optimal/references`` and ``optimal/search``.
* ``api/``: one mkdocstrings page per public module of the documented packages.

No kernel is compiled: env classes are never imported, only their source is parsed.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import griffe
import gymnasium as gym
import mkdocs_gen_files
import pandas as pd

import mdi_envs  # noqa: F401  (registers the ids)
from baselines.records import read_study
from baselines.tables import (
    brake_use_table,
    comparison_table,
    improvement_table,
    robustness_table,
)
from optimal import available_references, load_reference
from optimal.convergence import continuous_cost, is_chain, study_table

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "docs")]  # benchmarks/ is not installed
import headline  # noqa: E402  (docs/headline.py)

from benchmarks.report import targets_table  # noqa: E402

NAMESPACE = "mdi_envs/"
API_PACKAGES = ("mdi_envs.solvers", "mdi_envs.stepping", "mdi_envs.mechanics", "mdi_envs.envs",
                "mdi_envs.maneuvers", "mdi_envs.rollout", "optimal", "baselines")
LOADER = griffe.GriffeLoader(search_paths=[str(ROOT)], docstring_parser=griffe.Parser.google)


def write(path: str, text: str) -> None:
    """Write one generated page."""
    with mkdocs_gen_files.open(path, "w") as handle:
        handle.write(text)


def figures(paths: Iterable[Path]) -> list[str]:
    """Copy committed PNGs into the results pages' folder; a Markdown image paragraph each."""
    lines = []
    for png in paths:
        with mkdocs_gen_files.open(f"results/img/{png.name}", "wb") as handle:
            handle.write(png.read_bytes())
        lines += [f"![{png.stem}](img/{png.name})", ""]
    return lines


def table(rows: list[dict[str, Any]], floatfmt: str = ".4g") -> str:
    """A Markdown table of records (pandas ``to_markdown``)."""
    return pd.DataFrame(rows).to_markdown(index=False, floatfmt=floatfmt)


# --- environments -----------------------------------------------------------------------------

def env_ids() -> list[str]:
    """Every registered id of the ``mdi_envs/`` namespace, sorted."""
    return sorted(i for i in gym.registry if i.startswith(NAMESPACE))


def class_docstring(entry_point: str) -> str:
    """The docstring of ``module:Class``, read from the source without importing it."""
    module, name = entry_point.split(":")
    obj = LOADER.load(module)[name]
    return obj.docstring.value if obj.docstring else ""


def env_gif(env_id: str) -> Path | None:
    """``docs/assets/<Name>-vN.gif``, else the GIF of another id with the same entry point."""
    entry_point = gym.spec(env_id).entry_point
    same = [env_id] + [i for i in env_ids() if gym.spec(i).entry_point == entry_point]
    for candidate in same:
        gif = ROOT / "docs" / "assets" / f"{candidate.removeprefix(NAMESPACE)}.gif"
        if gif.exists():
            return gif
    return None


def objective(spec: gym.envs.registration.EnvSpec) -> str:
    """The objective an id's env optimizes ("time" unless its kwargs say otherwise)."""
    return str(spec.kwargs.get("objective", "time"))


def references_for(env_id: str) -> list[dict[str, Any]]:
    """The shipped references computed for ``env_id``, or for its env class and objective."""
    spec = gym.spec(env_id)
    rows = []
    for ref_name in available_references():
        meta = load_reference(ref_name).metadata
        ref_spec = gym.spec(meta["env_id"])
        if meta["env_id"] == env_id or (ref_spec.entry_point == spec.entry_point
                                        and meta["cost_kind"] == objective(spec)):
            rows.append({"reference": f"`{ref_name}`", "computed for": f"`{meta['env_id']}`",
                         "objective": meta["cost_kind"], "t_f [s]": meta["final_time"],
                         "cost": meta["cost"], "intervals N": meta["num_intervals"]})
    return rows


def env_page(env_id: str) -> str:
    """The Markdown page of one env id."""
    spec = gym.spec(env_id)
    name = env_id.removeprefix(NAMESPACE)
    lines = [f"# {name}", ""]
    gif = env_gif(env_id)
    if gif is not None:
        lines += [f"![{name}](../assets/{gif.name})", ""]
    lines += ["```python", "import gymnasium as gym", "import mdi_envs",
              f'env = gym.make("{env_id}")', "```", "",
              table([{"id": f"`{env_id}`", "entry point": f"`{spec.entry_point}`",
                      "vector entry point": f"`{spec.vector_entry_point}`",
                      "max_episode_steps": spec.max_episode_steps,
                      "kwargs": f"`{spec.kwargs}`" if spec.kwargs else ""}]), ""]
    refs = references_for(env_id)
    if refs:
        lines += ["## Optimal reference", "",
                  "Loaded with `optimal.load_reference(NAME)` (from "
                  "`optimal/references/NAME.json`); see [the references](../results/"
                  "references.md).", "", table(refs), ""]
    lines.append(class_docstring(str(spec.entry_point)))
    return "\n".join(lines) + "\n"


def env_pages() -> None:
    """``envs/index.md`` (a table of every id) and one page per id."""
    rows, nav = [], ["* [Environments](index.md)"]
    for env_id in env_ids():
        name = env_id.removeprefix(NAMESPACE)
        write(f"envs/{name}.md", env_page(env_id))
        nav.append(f"* [{name}]({name}.md)")
        doc = class_docstring(str(gym.spec(env_id).entry_point))
        first = doc.split("## Description", 1)[-1].strip().split("\n\n")[0].replace("\n", " ")
        rows.append({"id": f"[`{env_id}`]({name}.md)", "description": first.split(". ")[0]})
    write("envs/index.md", "# Environments\n\n`import mdi_envs` registers every id below "
          "with Gymnasium. Each page is generated from the env class docstring.\n\n"
          + table(rows) + "\n")
    write("envs/SUMMARY.md", "\n".join(nav) + "\n")


# --- results ----------------------------------------------------------------------------------

def load(path: Path) -> Any:
    """A committed JSON file."""
    return json.loads(path.read_text())


def machine_text(run: dict[str, Any]) -> str:
    """One line on the machine and commit a benchmark ran on."""
    machine = run.get("machine", {})
    if not machine:
        return ""
    load = machine.get("load_average_at_start")
    return (f"Run {machine.get('date', '?')[:10]} at commit `{machine.get('git_commit', '?')[:7]}`"
            f" on {machine.get('cpu_count', '?')} cores ({machine.get('cpu_model', '?')}), load "
            f"average at start {f'{load[0]:.1f}' if load else '?'}.")


BENCHMARKS = {  # file stem: (title, the command that writes it)
    "solvers": ("LCP solvers", "python -m mdi_envs bench solvers"),
    "fc3d": ("Spatial friction (Siconos fc3d problems)", "python -m mdi_envs bench fc3d"),
    "engine": ("Engine: the Moreau-Jean step", "python -m mdi_envs bench engine"),
    "envs": ("Environments: env.step and vector envs", "python -m mdi_envs bench envs"),
    "work_precision": ("Work-precision against MuJoCo and the event-driven reference",
                       "python -m mdi_envs bench precision"),
    "stress": ("Stress cases", "python -m mdi_envs bench stress"),
    "startup": ("Start-up", "python -m mdi_envs bench startup"),
    "control": ("Model-based control", "python -m mdi_envs bench control"),
    "vec_env_throughput": ("SB3 training throughput", "python -m benchmarks.vec_env_throughput"),
    "before_after": ("Before/after speed comparison",
                     "python -m benchmarks.before_after --before DIR"),
}


def solver_tables(run: dict[str, Any]) -> list[str]:
    """Lemke against QuantEcon: median time ratios, the fixed cost per call, the peer problems."""
    comparison = run["quantecon_comparison"]
    ratios = [{"problems": r["set"], "count": r["problems"],
               "driver / QuantEcon": r["median_ratio_driver"],
               "lemke_solve / QuantEcon": r["median_ratio_kernel"]}
              for r in comparison["median_ratios"]]

    def micro(entry: dict[str, Any]) -> float:
        return 1e6 * entry["time"]["median_s"]

    fixed = [{"problem": r["name"], "driver [µs]": micro(r["driver"]),
              "lemke_solve [µs]": micro(r["kernel"]), "QuantEcon [µs]": micro(r["quantecon"])}
             for r in run["fixed_cost"]]
    peers = [{"problem": r["name"], "n": r["n"],
              **{f"{entry} {key}": r[entry]["outcome"][key]
                 for entry in ("driver", "quantecon") for key in ("status", "iterations")},
              "residual (driver)": r["driver"]["outcome"]["residual"]}
             for r in comparison["problems"] if r["family"] == "siconos"]
    return ["Median time ratios of Lemke (through the public driver `solve_lcp`, and its "
            "compiled entry `lemke_solve`) to QuantEcon's `lcp_lemke`, same problems, same "
            "run:", "", table(ratios, floatfmt=".3g"), "", "Fixed cost per call:", "",
            table(fixed, floatfmt=".3g"), "", "The Siconos LCPs (status and pivots of both):",
            "", table(peers, floatfmt=".2g"), ""]


def benchmark_page() -> None:
    """``results/benchmarks.md``: the headline table, then per benchmark its targets and PNGs."""
    folder = ROOT / "benchmarks" / "results"
    lines = ["# Benchmark results", "",
             "Generated from the committed JSON in `benchmarks/results/` (written by "
             "`python -m mdi_envs bench` from the repository's root; `make bench` runs them "
             "all). What each benchmark measures: [the benchmarks guide]"
             "(../guide/benchmarks.md).", ""]
    headline = folder / "headline.json"
    if headline.exists():
        rows = load(headline)["rows"]
        lines += ["## Headline", "", "Every target of the suite, per benchmark "
                  "(`benchmarks/results/headline.json`, `benchmarks.report.targets_table`).", ""]
        for name in dict.fromkeys(r["benchmark"] for r in rows):
            lines += [f"**{name}**", "", targets_table(
                [{**r, "benchmark": None} for r in rows if r["benchmark"] == name]), ""]
    for stem, (title, command) in BENCHMARKS.items():
        path = folder / f"{stem}.json"
        if not path.exists():
            continue
        run = load(path)
        lines += [f"## {title}", "", f"`{command}` writes `benchmarks/results/{stem}.json`. "
                  + machine_text(run), ""]
        targets = None
        if run.get("targets"):
            lines += [targets_table(run["targets"]), ""]
        if stem == "solvers":
            lines += solver_tables(run)
        if stem == "stress":
            targets = [{"family": c["family"], "case": c["name"], "passed": c["passed"],
                        "criteria (value relation limit)": "; ".join(
                            f"{name} {float(k['value']):.3g} {k['relation']} "
                            f"{float(k['limit']):.3g}" for name, k in c["criteria"].items())}
                       for c in run["cases"]]
        elif stem == "fc3d":
            targets = [{"problem": p["name"], "n": p["n"], "contacts": p["contacts"],
                        **{m: p[m].get("status") if isinstance(p[m], dict) else p[m]
                           for m in run["solved_by_method"]}, "solved": p["solved"]}
                       for p in run["problems"]]
        elif stem == "vec_env_throughput":
            targets = run["results"]
        if targets:
            flat = [{k: v for k, v in r.items() if not isinstance(v, (dict, list))}
                    for r in targets]
            lines += [table(flat), ""]
        lines += figures(sorted(folder.glob(f"{stem}*.png")) + sorted(
            folder.glob("lemke_vs_quantecon.png") if stem == "solvers" else []))
    write("results/benchmarks.md", "\n".join(lines))


def comparison_page() -> None:
    """``results/comparison.md``: RL vs MPC vs optimal from ``baselines/comparison``."""
    folder = ROOT / "baselines" / "comparison"
    studies = headline.comparisons(folder)
    lines = ["# RL vs MPC vs optimal", "",
             "Generated from `baselines/comparison/compare_*.json` (written by "
             "`mdi-envs compare ENV --scales 0.01 0.1 --output baselines/comparison`; the v1 "
             "studies' DAgger rows with `--trained baselines/distilled --controllers DAgger`). "
             "Each controller plays 20 "
             "perturbed starts per run; success is the fraction reaching the goal, ratios are "
             "time (or effort) over the optimal reference's, over the successes; IQM and 95 % "
             "stratified-bootstrap CI over runs (rliable). The method: "
             "[the baselines guide](../guide/baselines.md).", "",
             headline.headline_frame(studies).to_markdown(index=False), "",
             "In full (`baselines.tables.comparison_table`): the nominal start, the compute per "
             "policy call (mean wall time), its real-time factor (over the env's control period) "
             "and the training budget of each row.", "",
             comparison_table(studies), ""]
    improvement = improvement_table(studies)
    if improvement:
        lines += ["## Probability of improvement", "",
                  "P(X > Y) of a run of trained algorithm X over a run of row Y (rliable; "
                  "`baselines.tables.improvement_table`), in success rate and in optimality "
                  "score (the optimum over the run's mean time or effort on its successes, 0 "
                  "without success); 0.5 is a tie. Against a heuristic floor it says whether "
                  "the algorithm beats the floor.", "", improvement, ""]
    brake = brake_use_table(studies)
    if brake:
        lines += ["## Brake use", "",
                  "How each controller uses the manipulator's brake over its perturbed episodes "
                  "(`baselines.tables.brake_use_table`), and when it is engaged from the "
                  "nominal start; the figures `brake_*.png` show every run.", "", brake, ""]
    lines += figures(sorted(folder.glob("*.png")))
    floors = ROOT / "baselines" / "heuristics.json"
    if floors.exists():
        from baselines.evaluation import aggregate
        from baselines.records import Study, from_json

        studies = [aggregate(from_json(Study, d)) for d in load(floors)]
        lines += ["## Heuristic floors", "",
                  "Controllers a reader understands in one line (`baselines.heuristics`; "
                  "[guide](../guide/baselines.md#heuristic-floors)), from "
                  "`baselines/heuristics.json` (`python -m baselines.heuristics`): success "
                  "from 20 starts per start perturbation and, in brackets, the time or effort "
                  "over the optimum's, over the successes.", "", robustness_table(studies), ""]
    lines += ["## Shipped policies", "",
              "Every trained run in `baselines/trained/` (`STEM.json`: the exact arguments, "
              "versions and commit; `STEM.zip`: the model). Training success is over the last "
              "100 training episodes; the evaluation is `mdi-envs train`'s own (deterministic "
              "actions, from the nominal start).", "", table(trained_rows()), ""]
    write("results/comparison.md", "\n".join(lines))


def trained_rows() -> list[dict[str, Any]]:
    """One row per shipped policy, from its ``STEM.json`` (``baselines.train.read_training``)."""
    from baselines.train import read_training

    rows = []
    for path in sorted((ROOT / "baselines" / "trained").glob("*.json")):
        run = read_training(path)
        rows.append({"policy": path.stem, "steps": run.num_timesteps, "copies": run.num_envs,
                     "wall time [min]": run.wall_time_s / 60,
                     "training success": run.train_last100.success_rate,
                     "evaluation success": run.evaluation.success_rate,
                     "commit": (run.commit or "")[:7]})
    return rows


def robustness_page() -> None:
    """``results/robustness.md``: success and ratio under perturbations and model mismatch."""
    folder = ROOT / "baselines" / "robustness"
    studies = [read_study(p) for p in sorted(folder.glob("robustness_*.json"))]
    lines = ["# Robustness", "",
             "Generated from `baselines/robustness/robustness_*.json` (written by "
             "`mdi-envs robustness all --output baselines/robustness`, the distilled rows of "
             "the v1 studies with `--trained baselines/distilled --controllers DAgger`; every "
             "episode is in `episodes.jsonl`). Each cell: success over 20 starts per run, and in "
             "brackets the time (or effort) over the optimum, over the successes.", "",
             robustness_table(studies), ""]
    lines += figures(sorted(folder.glob("*.png")))
    write("results/robustness.md", "\n".join(lines))


def references_page() -> None:
    """``results/references.md``: the shipped optimal references and their searches."""
    rows, refine = [], []
    for name in available_references():
        meta = load_reference(name).metadata
        replay = {r["substeps"]: r for r in meta["replay"]}
        rows.append({"reference": name, "env id": meta["env_id"], "objective": meta["cost_kind"],
                     "t_f [s]": meta["final_time"], "cost": meta["cost"],
                     "N": meta["num_intervals"], "residual": meta["residual"],
                     "replay error at h": replay[1]["state_error"],
                     "reaches goal at h": replay[1]["reaches_goal"],
                     "replay error at h/10": replay.get(10, {}).get("state_error"),
                     "commit": meta["commit"][:7]})
    lines = ["# Optimal references", "",
             "Generated from `optimal/references/*.json` (the metadata of each shipped "
             "reference, read by `optimal.load_reference`) and `optimal/search/*.json` (the "
             "global search and mesh refinement that produced it). Method: "
             "[the optimal-control guide](../guide/optimal.md).", "",
             "## Shipped references", "", table(rows, floatfmt=".6g"), "",
             "The replay plays the reference's controls open loop through the simulator at the "
             "reference's step h and at h/10 (state error at t_f; the references are optima of "
             "the h-discrete system).", ""]
    continuous = [load(p) for p in sorted((ROOT / "optimal" / "continuous").glob("*.json"))
                  if not p.stem.endswith("_refinement")]
    if continuous:
        lines += ["## Continuous-time optima", "",
                  "The mode sequence of a reference with its switching times and t_f (and the "
                  "robot's controls within its phases) optimized in continuous time "
                  "(`optimal/continuous/NAME.json`; [method](../guide/polish.md)). Cost: t_f "
                  "[s] or the effort integral.", "",
                  table([{"reference": c["name"],
                          "continuous-time cost": continuous_cost(c),
                          "h-discrete optimum": c.get("discrete_cost"),
                          "intervals N": c.get("discrete_num_intervals"),
                          "relative difference": c.get("relative_difference"),
                          "goal error": c.get("goal_error"),
                          "integrator": (c.get("integrator") or {}).get("method")}
                         for c in continuous], floatfmt=".7g"), ""]
    for path in sorted((ROOT / "optimal" / "continuous").glob("*_refinement.json")):
        lines += refinement_section(load(path))
        lines += figures(png for png in [path.with_suffix(".png")] if png.exists())
    for path in sorted((ROOT / "optimal" / "search").glob("*_search.json")):
        run = load(path)
        name = path.stem.removesuffix("_search")
        search = run["search"]
        lines += [f"## Search: {name}", "",
                  f"`mdi-envs optimize {name} --starts K --refine F1,F2,...` writes "
                  f"`{path.name}`: {search['starts']} starts, {search['solves']} fixed-pattern "
                  f"solves, best from start \"{search['best_start']}\". The 10 best distinct "
                  "optima: " + ", ".join(f"{c:.4f}" for c in search["distinct_optima"][:10])
                  + ".", ""]
        refine = [{"N": lv["num_intervals"], "cost": lv["cost"],
                   "t_f [s]": lv["final_time"], "converged": lv["converged"],
                   "shipped": i == run["shipped_level"]}
                  for i, lv in enumerate(run["refinement"]["levels"])]
        lines += ["Mesh refinement (each level starts from the coarser one):", "",
                  table(refine, floatfmt=".6g"), ""]
        lines += figures(png for png in [path.with_suffix(".png")] if png.exists())
    write("results/references.md", "\n".join(lines))


def refinement_section(study: dict[str, Any]) -> list[str]:
    """The h-discrete optimum per N against the continuous one (``optimal.convergence``)."""
    def shown(value: float) -> float | None:
        return value if math.isfinite(value) else None

    rows = [{"N": row["num_intervals"], "cost, pattern fixed": row["start_cost"],
             "cost after the search": row["cost"], "search rounds": row["max_rounds"],
             "change from the previous N": shown(row["change"]),
             "distance": shown(row["distance"]),
             "distance / optimum": shown(row["relative_distance"]),
             "observed order": shown(row["order"]), "wall time [min]": row["wall_time"] / 60}
            for row in study_table(study)]
    name = study["name"]
    if is_chain(study):
        command, method = "--chain --levels N,... --rounds R", (
            "the shipped reference re-solved on its grid, each finer level refined from the one "
            "before (its pattern repeated, its trajectory interpolated) and solved with that "
            "pattern fixed, then freed by the continuation and mode-searched for at most the "
            "given rounds")
    else:
        command, method = "--levels N,...", (
            "per N the discrete problem solved from the continuous optimum's mode sequence "
            "projected on the grid, fixed, then mode-searched for at most the given rounds")
    return [f"## Refinement toward the continuous optimum: {name}", "",
            f"`python -m optimal.convergence {name} {command}` writes "
            f"`optimal/continuous/{name}_refinement.json`: {method} "
            "([method](../guide/polish.md#refinement-toward-the-continuous-optimum)). The "
            f"distance is to the continuous optimum ({study['continuous_cost']:.7g}).", "",
            table(rows, floatfmt=".7g"), ""]


def search_page() -> None:
    """``results/search.md``: the Optuna studies of ``baselines/search/studies.db`` and plots."""
    import shutil
    import tempfile
    import warnings

    import optuna

    from baselines.search import summary

    folder = ROOT / "baselines" / "search"
    lines = ["# Hyperparameter search", "",
             "Generated from `baselines/search/studies.db` (Optuna; written by "
             "`python -m baselines.search run STUDY`, plots by `python -m baselines.search plot "
             "STUDY`). A trial's score is the success rate from 20 starts perturbed at 0.1, "
             "then the time or effort ratio ([method](../guide/baselines.md#hyperparameter-"
             "search)).", ""]
    with tempfile.TemporaryDirectory() as scratch, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        copy = Path(scratch) / "studies.db"  # read a copy: the build never writes the repo
        shutil.copy(folder / "studies.db", copy)
        url = f"sqlite:///{copy}"
        for study in optuna.get_all_study_summaries(url):
            result = summary(study.study_name, url)
            lines += [f"## {study.study_name}", "",
                      table([{"trials " + k.lower(): v for k, v in result["trials"].items()}
                             | {"trials to run": result["remaining"],
                                "CPU-hours spent": result["cpu_hours"],
                                "best trial": result.get("best_trial"),
                                "best score": result.get("best_score")}]), ""]
            if "best_params" in result:
                lines += ["Best trial's evaluation and settings:", "",
                          table([result["best_evaluation"]]), "",
                          table([result["best_params"]]), ""]
            lines += figures(sorted(folder.glob(f"{study.study_name}_*.png")))
    write("results/search.md", "\n".join(lines))


def results_pages() -> None:
    """Every results page, its index and its nav entries."""
    pages = {"comparison": "RL vs MPC vs optimal", "robustness": "Robustness",
             "references": "Optimal references", "benchmarks": "Benchmarks"}
    comparison_page()
    robustness_page()
    references_page()
    benchmark_page()
    if (ROOT / "baselines" / "search" / "studies.db").exists():
        search_page()
        pages["search"] = "Hyperparameter search"
    links = "".join(f"* [{title}]({page}.md)\n" for page, title in pages.items())
    write("results/index.md", "# Results\n\nEvery table on these pages is generated at build "
          "time from the committed results; every figure is a committed PNG.\n\n" + links)
    write("results/SUMMARY.md", "* [Results](index.md)\n" + links)


# --- API reference ----------------------------------------------------------------------------

def public_modules(package: str) -> Iterator[str]:
    """``package`` and its submodules whose dotted path has no ``_``-prefixed part."""
    root = LOADER.load(package)
    stack = [root]
    while stack:
        module = stack.pop()
        if any(part.startswith("_") for part in module.path.split(".")):
            continue
        yield module.path
        stack.extend(m for m in module.modules.values() if not m.is_alias)


def api_pages() -> None:
    """One mkdocstrings page per public module."""
    modules = sorted(m for package in API_PACKAGES for m in public_modules(package))
    for module in modules:
        write(f"api/{module}.md", f"# `{module}`\n\n::: {module}\n    options:\n"
              "      show_root_heading: false\n      show_submodules: false\n")
    write("api/index.md", "# API reference\n\nGenerated from the docstrings (griffe reads the "
          "source; nothing is imported).\n\n" + "\n".join(f"* [`{m}`]({m}.md)" for m in modules)
          + "\n")
    write("api/SUMMARY.md", "* [API reference](index.md)\n"
          + "\n".join(f"* [{m}]({m}.md)" for m in modules) + "\n")


env_pages()
results_pages()
api_pages()
