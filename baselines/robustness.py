"""Robustness of every controller: larger start perturbations and a model it does not know.

For (env id, objective) each controller row -- the optimal reference open loop, optionally the MPC
(``--mpc``, ``baselines.model_based``), and every trained seed of every algorithm -- is played
from ``--seeds`` perturbed starts under each condition of one study
(``baselines.evaluation.evaluate``): the start perturbation scales ``evaluation.SCALES`` (the env's
``reset_noise_scale``; default 0.01), then, at the default scale, the model mismatches in the
env only (``baselines.evaluation.MISMATCHES``: link masses +-10 % on the manipulator, chassis
mass +-10 % and the friction coefficients +-20 % on the robot).

``python -m baselines.robustness ENV_ID|all`` (or ``mdi-envs robustness``) writes
``robustness_ENV_OBJECTIVE.json`` (the ``baselines.records.Study``), ``.png`` (success against the
scale, one curve per controller; success under each mismatch) and ``robustness.md`` (per
controller and condition the success, mean over runs, and the time or effort ratio over the
successes, mean over the runs with successes; every study in the folder). ``--controllers
LABEL ... [--scales ...] [--no-mismatch | --mismatches LABEL ...]`` plays only those and merges
them into the study in the folder, so a slow controller's conditions can run one at a time.
Every finished episode is appended to ``episodes.jsonl`` there; ``--resume`` plays only the
episodes not in it, so a long run (the MPC under a mismatch: minutes per episode) can stop and
go on later.
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
