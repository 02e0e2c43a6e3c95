"""The baseline settings, read from rl-zoo3 YAML files shipped in ``baselines/hyperparams``.

One source: the files ``hyperparams/{algo}.yml`` (objective "time") and ``{algo}_{objective}.yml``
(other objectives: the diff drive's "effort") are rl-zoo3 hyperparameter files, keyed by the full
env id, so that ``python -m rl_zoo3.train --algo ppo --env mdi_envs/BlockableManipulator-v0
--gym-packages mdi_envs -conf baselines/hyperparams/ppo.yml`` trains with the settings that
``mdi-envs train`` reads here (``get_hyperparameters``). rl-zoo3 looks an entry up by env id alone,
so an objective that needs other settings needs its own file; the objective itself travels as the
env argument ``objective`` in ``env_kwargs``. An entry's rl-zoo3 keys map to ours: ``n_envs`` ->
``num_envs``, ``n_timesteps`` -> ``total_timesteps``, ``normalize: {norm_obs: false, norm_reward:
true}`` -> ``normalize_reward`` (the only normalization used), ``env_kwargs`` as is, ``policy``
must be ``MlpPolicy``; every other key is an SB3 constructor argument (``algo_kwargs``).
Algorithms: SB3's PPO and SAC and sb3-contrib's TQC and CrossQ on the default flattened Box action
spaces, and ``HybridPPO`` (``baselines.hybrid_ppo``: PPO with a categorical brake x Gaussian torque
policy) on the manipulator's native ``action_mode="hybrid"`` space ``Tuple(Discrete(2), Box(-1, 1,
(1,)))``; rl-zoo3 trains it through ``baselines.zoo``. Why the settings are what they are
(shaping discount, the effort reward, 10-step returns of the off-policy algorithms, budgets) is
in the baselines guide, ``docs/guide/baselines.md``. The seed is ``DEFAULT_SEED`` = 0 (rl-zoo3
takes it from ``--seed``, not from the file).
"""

from __future__ import annotations

import copy
import functools
from pathlib import Path
from typing import Any

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"
MANIPULATOR_V1 = "mdi_envs/BlockableManipulator-v1"
DIFF_DRIVE_V1 = "mdi_envs/DiffDriveRobot-v1"
DIFF_DRIVE_EFFORT_V1 = "mdi_envs/DiffDriveRobotEffort-v1"
ALGORITHMS = ("PPO", "SAC", "TQC", "CrossQ", "HybridPPO")
"""The algorithm names, canonical spelling (lookups are case-insensitive)."""
ALGORITHM_CLASSES = {
    "PPO": "stable_baselines3:PPO",
    "SAC": "stable_baselines3:SAC",
    "TQC": "sb3_contrib:TQC",
    "CrossQ": "sb3_contrib:CrossQ",
    "HybridPPO": "baselines.hybrid_ppo:HybridPPO",
    "DAgger": "baselines.distill:DAgger",
    "DAgger+PPO": "baselines.distill:DAgger",
}
"""Algorithm name -> "module:class" of its SB3-compatible class (imported on use, see
``baselines.train.algorithm_class``; this module imports no SB3). ``DAgger`` (the distilled
policies of ``baselines.distill``) and ``DAgger+PPO`` (those fine-tuned by ``baselines.finetune``)
are not trained by ``mdi-envs train``; they only load."""

HYPERPARAMS_DIR = Path(__file__).parent / "hyperparams"
"""The shipped rl-zoo3 hyperparameter files (package data)."""

DEFAULT_SEED = 0
"""The seed of a run when none is given (rl-zoo3: ``--seed 0``)."""

DEFAULT_OBJECTIVES = {MANIPULATOR: "time", DIFF_DRIVE: "time", MANIPULATOR_V1: "time",
                      DIFF_DRIVE_V1: "time", DIFF_DRIVE_EFFORT_V1: "effort"}
"""The trainable env ids and the objective used when none is given: a v0 id takes it as an env
argument (the manipulator has only "time"), a v1 id has one objective, its own."""

def parse_schedule(name: str, value: float | str) -> tuple[float, bool]:
    """(initial value, decays linearly to 0) of SB3 argument ``name``.

    ``value`` is a number or rl-zoo3's schedule string ``"lin_X"``: X times the fraction of
    training that remains.

    Raises:
        ValueError: a string that is not ``lin_<number>``.
    """
    if not isinstance(value, str):
        return float(value), False
    kind, _, initial = value.partition("_")
    if kind == "lin":
        try:
            return float(initial), True
        except ValueError:
            pass
    raise ValueError(f"{name}: {value!r} is not a schedule rl-zoo3 reads; "
                     "write lin_<initial value>")


_NORMALIZE_REWARD = {"norm_obs": False, "norm_reward": True}
"""rl-zoo3's ``normalize`` value of the entries with ``normalize_reward``."""


def canonical_algorithm(name: str) -> str:
    """The ``ALGORITHMS`` spelling of ``name`` ("ppo" -> "PPO", "hybridppo" -> "HybridPPO").

    An unknown name is returned unchanged (the caller's lookup then reports it).
    """
    return {algo.lower(): algo for algo in ALGORITHMS}.get(name.lower(), name)


def hyperparameter_file(algo: str, objective: str = "time") -> Path:
    """The rl-zoo3 file of ``algo``, ``objective``: ``{algo}.yml`` or ``{algo}_{objective}.yml``.

    The path exists only for the combinations of the table (``hyperparameter_table``).
    """
    name = canonical_algorithm(algo).lower() + ("" if objective == "time" else f"_{objective}")
    return HYPERPARAMS_DIR / f"{name}.yml"


def entry_from_zoo(zoo: dict[str, Any]) -> dict[str, Any]:
    """Our table entry of one rl-zoo3 YAML entry (see the module docstring for the mapping).

    Raises:
        ValueError: a ``policy`` other than ``MlpPolicy`` or an unsupported ``normalize``.
    """
    algo_kwargs = copy.deepcopy(zoo)
    num_envs = int(algo_kwargs.pop("n_envs", 1))
    total_timesteps = int(float(algo_kwargs.pop("n_timesteps")))
    env_kwargs = algo_kwargs.pop("env_kwargs", {})
    normalize = algo_kwargs.pop("normalize", None)
    if algo_kwargs.pop("policy", "MlpPolicy") != "MlpPolicy":
        raise ValueError(f"only policy MlpPolicy is supported, got {zoo['policy']!r}")
    if normalize not in (None, _NORMALIZE_REWARD):
        raise ValueError(f"only normalize {_NORMALIZE_REWARD} is supported, got {normalize!r}")
    return {"num_envs": num_envs, "total_timesteps": total_timesteps, "seed": DEFAULT_SEED,
            "algo_kwargs": algo_kwargs, "env_kwargs": env_kwargs,
            "normalize_reward": normalize is not None}  # fmt: skip


@functools.cache
def hyperparameter_table() -> dict[tuple[str, str, str], dict[str, Any]]:
    """The table read from ``HYPERPARAMS_DIR`` (once per process; the object is shared).

    Returns:
        (env id, objective, algorithm) -> {"num_envs", "total_timesteps", "seed", "algo_kwargs"
        (SB3 constructor arguments), "env_kwargs" (``gym.make`` arguments), "normalize_reward"
        (train on rewards scaled by ``VecNormalize``)}. The algorithm is the file name's first
        part, the objective the entry's ``env_kwargs["objective"]`` ("time" when absent).

    Raises:
        ValueError: an entry in a file whose name does not match its algorithm and objective.
    """
    import yaml

    table: dict[tuple[str, str, str], dict[str, Any]] = {}
    for path in sorted(HYPERPARAMS_DIR.glob("*.yml")):
        algo = canonical_algorithm(path.stem.split("_")[0])
        for env_id, zoo in yaml.safe_load(path.read_text()).items():
            entry = entry_from_zoo(zoo)
            objective = str(entry["env_kwargs"].get("objective", "time"))
            if hyperparameter_file(algo, objective) != path:
                raise ValueError(f"{path.name}: the {env_id} entry (objective {objective!r}) "
                                 f"belongs in {hyperparameter_file(algo, objective).name}")
            table[(env_id, objective, algo)] = entry
    return table


def get_hyperparameters(env_id: str, algo: str, objective: str | None = None) -> dict[str, Any]:
    """A deep copy of the table entry.

    Args:
        env_id: a key of ``DEFAULT_OBJECTIVES`` (the v0 and v1 mission ids).
        algo: an ``ALGORITHMS`` name (case-insensitive; HybridPPO: manipulator only).
        objective: "time" or "effort" (the v0 diff drive only); default
            ``DEFAULT_OBJECTIVES[env_id]``.

    Raises:
        KeyError: no entry for this combination (the message lists the known keys).
    """
    table = hyperparameter_table()
    objective = DEFAULT_OBJECTIVES.get(env_id) if objective is None else objective
    key = (env_id, str(objective), canonical_algorithm(algo))
    if key not in table:
        known = ", ".join(" ".join(k) for k in table)
        raise KeyError(f"no hyperparameters for {' '.join(map(str, key))}; known: {known}")
    return copy.deepcopy(table[key])


__all__ = [
    "ALGORITHMS", "ALGORITHM_CLASSES", "DEFAULT_SEED", "DEFAULT_OBJECTIVES", "DIFF_DRIVE",
    "DIFF_DRIVE_EFFORT_V1", "DIFF_DRIVE_V1", "HYPERPARAMS_DIR", "MANIPULATOR", "MANIPULATOR_V1",
    "canonical_algorithm", "entry_from_zoo", "get_hyperparameters", "hyperparameter_file",
    "hyperparameter_table", "parse_schedule",
]
