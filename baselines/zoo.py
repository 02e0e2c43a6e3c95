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

Every other algorithm needs no launcher (``python -m rl_zoo3.train``). Needs the ``rl`` extra.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

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
    module, _, function = COMMANDS[args[0]].partition(":")
    sys.argv = [f"{module.replace('.', '/')}.py", *args[1:]]
    getattr(importlib.import_module(module), function)()


if __name__ == "__main__":
    main()
