"""The benchmark suite: solver, engine and env speed, work-precision, start-up, stress.

Run ``python -m mdi_envs bench [NAME ...] [--quick]`` from the repository's root (``cli``) or
one module, e.g. ``python -m benchmarks.engine --quick``; each writes its JSON and PNGs, and
``headline`` collects every target into ``headline.md``. What each measures and how:
docs/guide/benchmarks.md.
"""
