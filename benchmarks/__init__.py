"""Benchmarks of the LCP solvers, the time-stepping engine (vs MuJoCo) and the environments.

Run ``python -m benchmarks.solvers``, ``python -m benchmarks.engine`` and
``python -m benchmarks.envs``.

Modules:
    problems: the seeded random LCP families and the Siconos peer problems.
    entries: the timed entry points (driver per method, ``lemke_solve``, QuantEcon).
    timing: interleaved wall-clock timing, first-call (compile) probes, machine information,
        load average and progress lines (shared by both benchmarks).
    first_call: a fresh-interpreter probe of each compiled entry's first-call time.
    report: Markdown tables, plots and the JSON record (``markdown_table``, ``format_us`` and
        ``write_json`` are shared).
    solvers: the command line: the work-size study and the comparison with QuantEcon.
    engine_scenes: the models of ``mdi_envs.mechanics``, their scenes and batched calls.
    engine_mujoco: the MuJoCo peer of the blockable manipulator (MJCF, steps, rollouts).
    engine_report: the engine benchmark's Markdown tables and plots.
    engine: the command line of the engine benchmark.
    envs: env.step through gym.make and vector-env throughput vs Acrobot-v1 and MuJoCo's
        InvertedDoublePendulum-v5 (its report: envs_report).
"""
