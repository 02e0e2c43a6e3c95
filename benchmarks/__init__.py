"""The benchmark suite: solvers, engine and envs speed, work-precision, numerical stress.

Run ``mdi-envs bench [NAME ...] [--quick]`` (``benchmarks.cli``) or each module alone, e.g.
``python -m benchmarks.engine --quick``. Each benchmark writes its JSON record and PNG plots;
``headline`` collects every target check into ``headline.md``.

Modules:
    cli: ``mdi-envs bench``; headline: the table of every target and verdict in one.
    report: shared Markdown tables (pandas), target checks, figures and the JSON record.
    timing: interleaved wall-clock timing, first-call probes, machine information, progress.
    solvers (solvers_report, entries, problems, first_call): LCP methods, work vs size, and
        our Lemke against QuantEcon's.
    engine (engine_scenes, engine_mujoco, engine_report): µs per step, single and batched,
        the shortcut ablation, the brake stop, against MuJoCo.
    envs (envs_report): env.step through gym.make and vector-env throughput vs Acrobot-v1 and
        MuJoCo's InvertedDoublePendulum-v5.
    work_precision (work_precision_mujoco, work_precision_report): error against wall time per
        scene, ours vs the event-driven reference and MuJoCo.
    fc3d: every FC3D method on the Siconos fc3d peer problems.
    stress: runs the stress cases of ``tests/stress`` (pytest) and writes their record.
    startup (startup_probe, _numba_floor): interpreter start to the first env step.
    vec_env_throughput: PPO training speed per vector-env backend.
    before_after (in_place_probe): speed of two trees alternated in one run.
"""
