r"""rl-zoo3's ``train`` and ``enjoy`` with ``HybridPPO`` among its algorithms.

rl-zoo3 has no plug-in point for an algorithm: ``--algo`` accepts the keys of its dict
``rl_zoo3.utils.ALGOS`` (SB3's and sb3-contrib's), and its hyperparameter files only name
policies, wrappers and callbacks. This launcher adds ``hybridppo`` ->
``baselines.hybrid_ppo.HybridPPO`` to that dict and runs rl-zoo3's own entry point with the
other arguments unchanged, so the shipped ``baselines/hyperparams/hybridppo.yml`` trains and
plays as any rl-zoo3 entry (HybridPPO wraps the env's hybrid Tuple action space itself)::

    python -m baselines.zoo train --algo hybridppo --env mdi_envs/BlockableManipulator-v0 \
        --gym-packages mdi_envs -conf baselines/hyperparams/hybridppo.yml --seed 0
    python -m baselines.zoo enjoy --algo hybridppo --env mdi_envs/BlockableManipulator-v0 \
        --gym-packages mdi_envs --no-render

rl-zoo3 (2.9) builds its evaluation env (``--eval-freq``, every 25,000 steps by default) with
the env arguments of the command line only, not those of the hyperparameter file: with
``-conf`` alone it evaluates on the env's defaults (the diff drive's "time" objective for an
"effort" entry; for HybridPPO the Box action space, which fails at the first evaluation). The
launcher's ``train`` therefore adds ``--eval-env-kwargs`` with the entry's ``env_kwargs`` when
the command gives none (``eval_env_arguments``). Every other algorithm needs no launcher:
``python -m rl_zoo3.train`` with ``--eval-env-kwargs`` spelled out (or ``--eval-freq -1``), or
this launcher. Needs the ``rl`` extra.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence
from pathlib import Path

ZOO_ALGORITHMS = {"hybridppo": "baselines.hybrid_ppo:HybridPPO"}
"""rl-zoo3 ``--algo`` name -> "module:class" added to ``rl_zoo3.utils.ALGOS``."""

COMMANDS = {"train": "rl_zoo3.train:train", "enjoy": "rl_zoo3.enjoy:enjoy"}
"""Launcher command -> rl-zoo3's entry point ("module:function", reads ``sys.argv``)."""


def register_algorithms() -> None:
    """Add ``ZOO_ALGORITHMS`` to rl-zoo3's algorithm dict (idempotent)."""
    from rl_zoo3.utils import ALGOS

    for name, target in ZOO_ALGORITHMS.items():
        module, _, attribute = target.partition(":")
        ALGOS[name] = getattr(importlib.import_module(module), attribute)


def eval_env_arguments(args: Sequence[str]) -> list[str]:
    """``--eval-env-kwargs`` with the ``-conf`` entry's ``env_kwargs`` for rl-zoo3's ``train``.

    Args:
        args: rl-zoo3's ``train`` arguments.

    Returns:
        ``["--eval-env-kwargs", "key:repr(value)", ...]``, or ``[]`` when ``args`` already set
        them, name no ``-conf``/``--conf-file`` YAML file or ``--env``, or the entry has none.
    """
    import yaml

    def value(*flags: str) -> str | None:
        positions = [i for i, arg in enumerate(args) if arg in flags and i + 1 < len(args)]
        return args[positions[-1] + 1] if positions else None

    conf, env_id = value("-conf", "--conf-file"), value("--env")
    if "--eval-env-kwargs" in args or conf is None or env_id is None or not conf.endswith(
            (".yml", ".yaml")):  # fmt: skip
        return []
    entry = yaml.safe_load(Path(conf).read_text()).get(env_id) or {}
    env_kwargs = entry.get("env_kwargs") or {}
    if not env_kwargs:
        return []
    return ["--eval-env-kwargs", *(f"{key}:{item!r}" for key, item in env_kwargs.items())]


def main(argv: Sequence[str] | None = None) -> None:
    """Run ``rl_zoo3.train`` or ``rl_zoo3.enjoy`` (first argument) with the rest of ``argv``.

    Raises:
        SystemExit: no or an unknown command (the message lists ``COMMANDS``).
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] not in COMMANDS:
        raise SystemExit(f"usage: python -m baselines.zoo {{{','.join(COMMANDS)}}} "
                         "[rl-zoo3 arguments]")  # fmt: skip
    register_algorithms()
    command, rest = args[0], args[1:]
    if command == "train":
        rest += eval_env_arguments(rest)
    module, _, function = COMMANDS[command].partition(":")
    sys.argv = [f"{module.replace('.', '/')}.py", *rest]
    getattr(importlib.import_module(module), function)()


if __name__ == "__main__":
    main()
