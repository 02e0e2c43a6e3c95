"""Model-based controller rows: the time-varying LQR, the tracking MPC, the shrinking-horizon MPC.

Each plays along the optimal reference of (env id, objective).
``lqr_controller`` plays ``optimal.lqr.TimeVaryingLQR`` (microseconds per step); it is registered
in ``baselines.evaluation.CONTROLLER_FACTORIES``, so every study plays it. ``tracking_controller``
plays ``optimal.tracking.TrackingMPC`` (its window NLPs take 10-60 s to build, once per row), on
the robot supervised by ``Recovering``. ``mpc_controller`` plays ``ShrinkingHorizonMPC`` in the
env configured like the reference's open-loop replay (one env step per transcription interval,
``env_options``), with twice the reference's steps for time-optimal objectives. The two MPCs cost
0.1-1 s (shrinking horizon) and milliseconds (tracking) per step and are played with ``mdi-envs
compare ... --mpc``; they need CasADi (the ``optimal`` extra), without which their rows are left
out. One controller serves every episode of a row, so the NLPs it built are reused.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from typing import Any

import gymnasium as gym

from baselines.evaluation import REFERENCE_NAMES, Controller
from baselines.heuristics import parking_follower
from mdi_envs.rollout import Policy
from optimal.problems import make_problem, model_of
from optimal.references import Reference, load_reference
from optimal.replay import env_options

MPC = "MPC (shrinking horizon)"
"""The label of the MPC rows."""

TRACKING = "MPC (tracking window)"
"""The label of the tracking MPC rows."""

LQR = "LQR (time-varying)"
"""The label of the LQR rows."""

STATE_INDEXED = "state-indexed"
"""Appended to the label of a state-indexed row (``INDEX_WINDOW``)."""

PARKING = "parking"
"""Appended to the label of a state-indexed row supervised by ``Recovering``."""

INDEX_WINDOW = 10
"""The state-indexed controllers' search window [reference nodes] (``optimal.observations``)."""


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
    """The tracking MPC along the reference of (env id, objective), supervised on the robot.

    On time-optimal tasks it turns state-indexed (``INDEX_WINDOW``) once it finds less friction
    than its model (``TrackingMPC.index_on_less_friction``); on the effort tasks, whose episode
    ends with the reference's horizon, it stays time-indexed. None without a reference or CasADi.
    """
    from optimal.tracking import TrackingMPC

    return reference_controller(TRACKING, TrackingMPC, env_id, objective, supervised=True,
                                index_window=INDEX_WINDOW if objective == "time" else 0,
                                index_on_less_friction=True)


class Recovering:
    """A reference tracker on the robot, then, past the reference's end, the parking follower.

    The policy is ``tracker`` (a ``StateFeedbackPolicy``) until it has acted for the reference's
    last interval N - 1 (``reference_interval`` of its ``last_step``: after N steps if
    time-indexed and on time); then, unless the episode has ended in the goal box, it switches
    to ``parking_follower`` from the observed pose, with the nominal model's parameters (the
    follower does not adapt to a mismatch). A time-optimal reference rides the traction limit:
    under more friction or mass than the model the robot ends it at rest outside the goal box,
    where the rolling traction holds it still and the LQR's gain about the goal is zero.

    Args:
        tracker: the policy along the reference (reset by ``reset``).
        reference: the robot's reference it tracks.
        env: an env of the played configuration (its ``dt`` and action torque scale are read).
    """

    def __init__(self, tracker: Any, reference: Reference, env: gym.Env[Any, Any]) -> None:
        self.tracker = tracker
        self.last_node = len(reference.tau) - 1
        self._parameters = model_of(make_problem(reference.name))[1]
        self._dt = float(env.unwrapped.dt)
        self._torque = float(env.unwrapped.scene.max_wheel_torque)
        self._step = 0
        self.recovery: Policy | None = None

    def reset(self) -> None:
        """A new episode: the tracker's, and no recovery."""
        self.tracker.reset()
        self._step, self.recovery = 0, None

    def __call__(self, observation: Any) -> Any:
        """The env action at this step."""
        if self.recovery is None and self._step and self.tracker.reference_interval(
                self.tracker.last_step) >= self.last_node:
            self.recovery = parking_follower(self._parameters, self._dt, self._torque,
                                             observation)
        self._step += 1
        return (self.tracker if self.recovery is None else self.recovery)(observation)

    def applied(self, action: Any) -> None:
        """The tracker's ``StateFeedbackPolicy.applied`` while it acts (the follower keeps none)."""
        if self.recovery is None:
            self.tracker.applied(action)


def tracking_state_controller(env_id: str, objective: str) -> Controller | None:
    """The tracking MPC, state-indexed (``INDEX_WINDOW``) and without ``Recovering``.

    None without a reference or CasADi.
    """
    from optimal.tracking import TrackingMPC

    return reference_controller(f"{TRACKING}, {STATE_INDEXED}", TrackingMPC, env_id, objective,
                                index_window=INDEX_WINDOW)


def tracking_state_parking_controller(env_id: str, objective: str) -> Controller | None:
    """The state-indexed tracking MPC, on the robot supervised by ``Recovering``.

    Once its nearest reference node is the last one and the episode goes on (the robot at rest
    outside the goal box, or still short of it), the parking follower takes over. None without
    a reference or CasADi.
    """
    from optimal.tracking import TrackingMPC

    return reference_controller(f"{TRACKING}, {STATE_INDEXED}, {PARKING}", TrackingMPC, env_id,
                                objective, supervised=True, index_window=INDEX_WINDOW)


def reference_controller(label: str, controller_class: Callable[[Reference], Any], env_id: str,
                         objective: str, needs_casadi: bool = True, supervised: bool = False,
                         **attributes: Any) -> Controller | None:
    """The row ``label``: ``controller_class(reference)`` along the reference of the task.

    None without a reference for (env id, objective), or without CasADi when ``needs_casadi``.
    The controller is built at the row's first episode (a row not played costs nothing) and
    serves every episode, reset at each (its built NLPs or gains stay). ``supervised``: on the
    robot (a model without brakes) it is wrapped in ``Recovering``. ``attributes`` are set on
    the controller, e.g. its ``StateFeedbackPolicy.index_window`` (default 0: time-indexed).
    """
    name = REFERENCE_NAMES.get((env_id, objective))
    if name is None or (needs_casadi and importlib.util.find_spec("casadi") is None):
        return None
    reference = load_reference(name)
    built: list[Any] = []

    def make_policy(env: Any) -> Any:
        if not built:
            built.append(controller_class(reference))
            for name, value in attributes.items():
                setattr(built[0], name, value)
        policy = built[0]
        if supervised and not policy.has_brake:
            policy = Recovering(policy, reference, env)
        policy.reset()
        return policy

    return Controller(label, make_policy, row_env_options(reference))


EXPERTS: dict[str, Callable[[str, str], Controller | None]] = {
    "lqr": lqr_controller, "tracking": tracking_controller,
    "tracking-state": tracking_state_controller,
    "tracking-state-parking": tracking_state_parking_controller, "mpc": mpc_controller,
}  # fmt: skip
"""Feedback expert name -> its ``ControllerFactory`` (``baselines.evaluation``), the experts of
the distillation and the datasets: the time-varying LQR (microseconds per step), the tracking
MPC (milliseconds; time- or state-indexed, the latter with or without the parking supervisor),
the shrinking-horizon MPC (0.1-1 s)."""


__all__ = ["EXPERTS", "INDEX_WINDOW", "LQR", "MPC", "PARKING", "STATE_INDEXED", "TRACKING",
           "Recovering", "lqr_controller", "mpc_controller", "reference_controller",
           "row_env_options", "tracking_controller", "tracking_state_controller",
           "tracking_state_parking_controller"]
