"""Precompile every kernel an environment id uses into the disk cache (``mdi-envs compile``).

Each id is compiled in a worker process of its own (the ids share no specialised kernel, and
the processes use every core), by doing what a user does first: ``gym.make`` and
``gym.make_vec`` with each documented variant, a reset and a step, and the model's stepper
from Python (``step``, ``step_batch``, ``in_place``). Later processes load the machine code
from the cache (``mdi_envs._kernel_cache``) instead of compiling it.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

VARIANTS: dict[str, tuple[dict[str, Any], ...]] = {
    "mdi_envs/BlockableManipulator-v0": ({}, {"action_mode": "hybrid"},
                                         {"action_mode": "brake_force"}),
    "mdi_envs/DiffDriveRobot-v0": ({"objective": "time"}, {"objective": "effort"}),
}
"""Keyword arguments of the variants a registered id documents (default: the plain id)."""

STAGES = ("env", "vector env", "variants", "stepper")
"""What ``compile_env`` compiles, in order (one progress step each)."""

MAKE_STAGES = ("env", "variants")
"""The stages ``gym.make`` needs (each id and its documented variants): on an empty cache about
60 % of the compile time of all ``STAGES``."""


def compile_env(env_id: str, report: Callable[[str, float], None] | None = None,
                stages: Iterable[str] = STAGES) -> float:
    """Compile (or load from the cache) the kernels of ``env_id`` in this process.

    Args:
        env_id: a registered ``mdi_envs/...`` id.
        report: called with (stage, seconds) after each stage compiled.
        stages: which of ``STAGES`` to compile.

    Returns:
        Seconds taken.

    Raises:
        ValueError: ``env_id`` is not one of ``mdi_envs.ENV_IDS``, or a stage not in ``STAGES``.
    """
    import gymnasium as gym
    import numpy as np

    from mdi_envs import ENV_IDS

    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env id {env_id!r}; registered: {', '.join(ENV_IDS)}")
    stages = _checked(stages)
    started = time.perf_counter()
    variants = VARIANTS.get(env_id, ({},))

    def run(stage: str, action: Callable[[], Any]) -> None:
        if stage not in stages:
            return
        began = time.perf_counter()
        action()
        if report is not None:
            report(stage, time.perf_counter() - began)

    def single(options: dict[str, Any]) -> Any:
        env = gym.make(env_id, **options)
        env.reset(seed=0)
        env.step(env.action_space.sample())
        return env.unwrapped

    def vector() -> None:
        for options in variants[:1]:
            env = gym.make_vec(env_id, num_envs=2, **options)
            env.reset(seed=0)
            env.step(env.action_space.sample())

    def stepper() -> None:
        stepper = single(variants[0]).scene.stepper
        n = stepper.num_dofs
        state = np.zeros(n)
        stepper.step(state, state, np.zeros(stepper.num_inputs))
        q, u = np.zeros((2, n)), np.zeros((2, n))
        stepper.step_batch(q, u, np.zeros((2, stepper.num_inputs)))
        stepper.in_place(state, state).step()

    run(STAGES[0], lambda: single(variants[0]))
    run(STAGES[1], vector)
    run(STAGES[2], lambda: [single(options) for options in variants[1:]])
    run(STAGES[3], stepper)
    return time.perf_counter() - started


def _checked(stages: Iterable[str]) -> tuple[str, ...]:
    """``stages`` as a tuple, each one of ``STAGES`` (ValueError naming any other)."""
    stages = tuple(stages)
    unknown = [stage for stage in stages if stage not in STAGES]
    if unknown:
        raise ValueError(f"unknown stage(s) {unknown}; known: {', '.join(STAGES)}")
    return stages


def _compile_in_worker(env_id: str, queue: Any, stages: tuple[str, ...]) -> float:
    return compile_env(env_id, lambda stage, seconds: queue.put((env_id, stage, seconds)),
                       stages)


def compile_envs(env_ids: Iterable[str], jobs: int | None = None, progress: bool = True,
                 stages: Iterable[str] = STAGES) -> dict[str, float]:
    """Compile ``stages`` of ``env_ids`` in ``jobs`` worker processes (default: all cores).

    Shows a progress bar (one step per id and stage) unless ``progress`` is False. Returns
    each id's seconds, as measured in its worker.

    Raises:
        ValueError: an unknown id or stage (before anything starts).
        RuntimeError: a worker failed (the message names the id and the error).
    """
    from tqdm import tqdm

    from mdi_envs import ENV_IDS

    ids = list(dict.fromkeys(env_ids))
    unknown = [env_id for env_id in ids if env_id not in ENV_IDS]
    if unknown:
        raise ValueError(f"unknown env id(s) {unknown}; registered: {', '.join(ENV_IDS)}")
    stages = _checked(stages)
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(ids)))
    context = multiprocessing.get_context("spawn")  # fresh interpreters, nothing inherited
    seconds: dict[str, float] = {}
    with context.Manager() as manager, tqdm(total=len(ids) * len(stages), unit="stage",
                                            disable=not progress) as bar:
        queue = manager.Queue()
        with ProcessPoolExecutor(jobs, mp_context=context) as pool:
            futures = {pool.submit(_compile_in_worker, env_id, queue, stages): env_id
                       for env_id in ids}
            pending = set(futures)
            while pending:
                while not queue.empty():
                    env_id, stage, took = queue.get()
                    bar.set_postfix_str(f"{env_id.split('/')[-1]}: {stage} {took:.1f} s")
                    bar.update()
                done = [future for future in pending if future.done()]
                for future in as_completed(done):
                    pending.discard(future)
                    try:
                        seconds[futures[future]] = future.result()
                    except Exception as error:
                        raise RuntimeError(f"compiling {futures[future]} failed: "
                                           f"{error!r}") from error
                time.sleep(0.05)
            while not queue.empty():
                queue.get()
                bar.update()
    return seconds


__all__ = ["MAKE_STAGES", "STAGES", "VARIANTS", "compile_env", "compile_envs"]
