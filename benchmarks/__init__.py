"""Benchmarks of the complementarity solvers (run ``python -m benchmarks.solvers``).

Modules:
    problems: the seeded random LCP families and the Siconos peer problems.
    entries: the timed entry points (driver per method, ``lemke_solve``, QuantEcon).
    timing: interleaved wall-clock timing, first-call (compile) probes and machine information.
    first_call: a fresh-interpreter probe of each compiled entry's first-call time.
    report: Markdown tables, plots and the JSON record.
    solvers: the command line: the work-size study and the comparison with QuantEcon.
"""
