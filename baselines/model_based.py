"""Model-based controller rows of the comparison: the time-varying LQR, the shrinking-horizon MPC.

``lqr_controller(env_id, objective)`` plays ``optimal.lqr.TimeVaryingLQR`` along the reference of
(env id, objective), in the same env configuration as the MPC below; it costs microseconds per
step and is registered in ``baselines.evaluation.CONTROLLER_FACTORIES``, so every study plays it.
``tracking_controller`` plays ``optimal.tracking.TrackingMPC`` (its window NLPs take 10-60 s to
build, once per row, at its first episode); ``--mpc`` adds it with the shrinking-horizon MPC.

``mpc_controller(env_id, objective)`` plays ``ShrinkingHorizonMPC`` around the reference of (env
id, objective) in the env configured like the reference's open-loop replay (one env step per
transcription interval, ``env_options``), with twice the reference's steps for time-optimal
objectives (a perturbed start may need longer than the optimum; the effort objectives keep their
fixed horizon). One controller serves every episode of a row, so the NLPs it built are reused.
``mdi-envs compare ... --mpc`` adds it; it is not in ``baselines.evaluation.CONTROLLER_FACTORIES``,
which every comparison and test plays, because it costs 0.1-1 s of compute per env step. Needs
CasADi (the ``optimal`` extra); without it the row is left out.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from typing import Any

from baselines.evaluation import REFERENCE_NAMES, Controller
from optimal.references import Reference, load_reference
from optimal.replay import env_options

MPC = "MPC (shrinking horizon)"
"""The label of the MPC rows."""

TRACKING = "MPC (tracking window)"
"""The label of the tracking MPC rows."""

LQR = "LQR (time-varying)"
"""The label of the LQR rows."""


def row_env_options(reference: Reference) -> dict[str, Any]:
    """The reference's env options; time-optimal objectives get twice its steps."""
    options = env_options(reference)
    options.pop("reset_noise_scale")
    if reference.metadata["cost_kind"] == "time":
        options["max_episode_steps"] = 2 * len(reference.tau)
    return options


def lqr_controller(env_id: str, objective: str) -> Controller | None:
    """The LQR along the reference of (env id, objective); None without a reference."""
    from optimal.lqr import TimeVaryingLQR

    return reference_controller(LQR, TimeVaryingLQR, env_id, objective, needs_casadi=False)


def mpc_controller(env_id: str, objective: str) -> Controller | None:
    """The MPC around the reference of (env id, objective); None without a reference or CasADi."""
    from optimal.mpc import ShrinkingHorizonMPC

    return reference_controller(MPC, ShrinkingHorizonMPC, env_id, objective)


def tracking_controller(env_id: str, objective: str) -> Controller | None:
    """The tracking MPC along the reference of (env id, objective); None without one or CasADi."""
    from optimal.tracking import TrackingMPC

    return reference_controller(TRACKING, TrackingMPC, env_id, objective)


def reference_controller(label: str, controller_class: Callable[[Reference], Any], env_id: str,
                         objective: str, needs_casadi: bool = True) -> Controller | None:
    """The row ``label``: ``controller_class(reference)`` along the reference of the task.

    None without a reference for (env id, objective), or without CasADi when ``needs_casadi``.
    The controller is built at the row's first episode (a row not played costs nothing) and
    serves every episode, reset at each (its built NLPs or gains stay).
    """
    name = REFERENCE_NAMES.get((env_id, objective))
    if name is None or (needs_casadi and importlib.util.find_spec("casadi") is None):
        return None
    reference = load_reference(name)
    built: list[Any] = []

    def make_policy(_env: Any) -> Any:
        if not built:
            built.append(controller_class(reference))
        built[0].reset()
        return built[0]

    return Controller(label, make_policy, row_env_options(reference))


EXPERTS: dict[str, Callable[[str, str], Controller | None]] = {
    "lqr": lqr_controller, "tracking": tracking_controller, "mpc": mpc_controller,
}  # fmt: skip
"""Feedback expert name -> its ``ControllerFactory`` (``baselines.evaluation``), the experts of
the distillation and the datasets: the time-varying LQR (microseconds per step), the tracking
MPC (milliseconds), the shrinking-horizon MPC (0.1-1 s)."""


__all__ = ["EXPERTS", "LQR", "MPC", "TRACKING", "lqr_controller", "mpc_controller",
           "reference_controller", "row_env_options", "tracking_controller"]
