"""First-call probe: run in a fresh interpreter, prints JSON of import and first-call times."""

from __future__ import annotations

import importlib
import json

from benchmarks.timing import seconds


def main() -> None:
    """Measure and print the report as JSON on stdout."""
    import_times = {
        "mdi_envs.solvers.lcp": seconds(lambda: importlib.import_module("mdi_envs.solvers.lcp")),
        "quantecon.optimize": seconds(lambda: importlib.import_module("quantecon.optimize")),
    }
    from benchmarks import problems as entries

    problem = entries.random_problem("spd", 5, 0)
    probes = [entries.KERNEL, *map(entries.driver_entry, entries.LCP_METHODS), entries.QUANTECON]
    first_call = {e.name: seconds(lambda e=e: e.solve(problem.M, problem.q)) for e in probes}
    second_call = {e.name: seconds(lambda e=e: e.solve(problem.M, problem.q)) for e in probes}
    report = {"import_s": import_times, "first_call_s": first_call, "second_call_s": second_call}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
