"""Robustness of every controller: larger start perturbations and a model it does not know.

``python -m baselines.robustness``, the same command as ``mdi-envs robustness`` (its arguments
and outputs: ``baselines.cli.ROBUSTNESS`` and ``robustness_arguments``; the study itself:
``baselines.evaluation.evaluate`` under the conditions ``evaluation.SCALES`` and
``evaluation.MISMATCHES``).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m baselines.robustness ENV_ID|all [--objective T] [--seeds N] [--mpc] ...``."""
    from baselines.cli import ROBUSTNESS, robustness_arguments, run_robustness

    parser = argparse.ArgumentParser(prog="python -m baselines.robustness",
                                     description=ROBUSTNESS)
    robustness_arguments(parser)
    return run_robustness(parser.parse_args(argv))


__all__ = ["main"]


if __name__ == "__main__":
    raise SystemExit(main())
