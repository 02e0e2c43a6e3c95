"""The benchmark suite: solvers, engine and envs speed, work-precision, numerical stress.

Run ``mdi-envs bench [NAME ...] [--quick]`` (``benchmarks.cli``; NAME in solvers, engine, envs,
precision, stress) or each module alone, e.g. ``python -m benchmarks.stress --quick``.

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
    work_precision: error against wall time per scene, ours vs the event-driven reference and
        MuJoCo (work_precision_mujoco: the MuJoCo ball and arm; work_precision_report).
    stress: Zeno balls, brake toggling, dt and mu sweeps, overdrive, degenerate LCPs, long
        horizons, each with pass/fail criteria (stress_report: criteria, table, plot).
    cli: ``mdi-envs bench``; headline: the table of every target and verdict in one.
"""
