"""Scenes of the engine benchmark: the models, their representative states, their batched calls.

Copy i of N gets scene ``i mod k`` of its model's k scenes; each timed call restarts from them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from benchmarks.timing import timed_call
from mdi_envs import mechanics
from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping._kernel import INFO_STATUS

TIME_STEP = 1e-3  # [s] of every stepper and of MuJoCo
TRESCA_BOUND = 0.5  # [N m] the Tresca scenes' brake bound (MuJoCo: frictionloss)
MOTOR_TORQUE = 1.0  # [N m] on alpha in every manipulator scene (MuJoCo: joint 1)
MANIPULATOR_Q = (0.3, 0.8)  # [rad] (alpha, beta): relative angle 0.5
MANIPULATOR_U = (0.5, 1.0)  # [rad/s]: relative velocity 0.5 (an engaged brake impacts)


@dataclass(frozen=True)
class Scene:
    """One state and input of one model."""

    name: str
    description: str
    q: tuple[float, ...]
    u: tuple[float, ...]
    tau: tuple[float, ...]
    brake: tuple[float, ...] = ()

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """(q, u, tau, brake_bound) as float arrays; brake_bound None for brakeless models."""
        brake = np.array(self.brake, dtype=float) if self.brake else None
        return np.array(self.q), np.array(self.u), np.array(self.tau), brake


@dataclass(frozen=True)
class ModelCase:
    """A model under test with its scenes."""

    label: str
    model: Any
    scenes: tuple[Scene, ...]
    mix: tuple[str, ...] = ()

    @property
    def mix_scenes(self) -> tuple[Scene, ...]:
        """The scenes of the batched mix."""
        return tuple(self.scene(n) for n in self.mix) if self.mix else self.scenes

    def scene(self, name: str) -> Scene:
        """The scene called ``name``."""
        return next(s for s in self.scenes if s.name == name)


def _ball_scenes(radius: float) -> tuple[Scene, ...]:
    return (
        Scene("resting", "at rest on the ground: the contact is closed at every step",
              (0.0, radius), (0.0, 0.0), (0.0,)),
        Scene("bouncing", "on the ground, falling at 1 m/s: an impact (eps = 0.8), then bounces "
              "that settle within 0.8 s", (0.0, radius), (0.3, -1.0), (0.0,)),
        Scene("in flight", "1000 km up, at rest: the contact stays open (no solve)",
              (0.0, 1e6), (0.0, 0.0), (0.0,)),
    )


BLOCK_SCENES = (
    Scene("sticking", "at rest on the slope, pushed uphill by 1 N: static friction holds it",
          (0.0, 0.0), (0.0, 0.0), (-1.0,)),
    Scene("sliding", "sliding down at 1 m/s, no push: kinetic friction, accelerating at "
          "0.4 m/s^2", (0.0, 0.0), (1.0, 0.0), (0.0,)),
)


_ARM = {"q": MANIPULATOR_Q, "u": MANIPULATOR_U, "tau": (MOTOR_TORQUE,)}
MANIPULATOR_SCENES = (
    Scene("engaged", "brake engaged (bound inf), relative velocity 0.5 rad/s: a plastic brake "
          "impact, then a rigid arm", brake=(np.inf,), **_ARM),
    Scene("released", "brake released (bound 0): no constraint, no solve", brake=(0.0,), **_ARM),
    Scene("tresca", f"Tresca brake, bound {TRESCA_BOUND} N m: slipping (LCP of size 2)",
          brake=(TRESCA_BOUND,), **_ARM),
)


DIFF_DRIVE_SCENES = (
    Scene("rolling", "from rest, equal wheel torques 0.5 N m: both wheels roll (mode 2)",
          (0.0,) * 5, (0.0,) * 5, (0.5, 0.5)),
    Scene("turning", "from rest, wheel torques 0.2 / 0.8 N m: rolls along an arc (mode 2)",
          (0.0,) * 5, (0.0,) * 5, (0.2, 0.8)),
    Scene("slipping", "from rest, wheel torques 5 N m: both wheels spin (mode 5)",
          (0.0,) * 5, (0.0,) * 5, (5.0, 5.0)),
)


def model_cases(names: Sequence[str]) -> list[ModelCase]:
    """The model cases of ``names`` (among ball, block, manipulator, diff_drive), in that order."""
    ball = mechanics.BouncingBall
    available = {
        "ball": ModelCase("ball", ball, _ball_scenes(ball.Parameters().radius),
                          mix=("resting", "bouncing")),
        "block": ModelCase("block", mechanics.SlidingBlock, BLOCK_SCENES),
        "manipulator": ModelCase("manipulator", mechanics.BlockableManipulator,
                                 MANIPULATOR_SCENES),
        "diff_drive": ModelCase("diff_drive", mechanics.DiffDriveRobot, DIFF_DRIVE_SCENES),
    }
    return [available[n] for n in names]


def batch_arrays(case: ModelCase, num_copies: int, scenes: Sequence[Scene] | None = None
                 ) -> tuple[np.ndarray, ...]:
    """(Q, U, TAU, BRAKE) for ``num_copies`` copies; copy i gets scene i mod len(scenes)."""
    chosen = list(scenes or case.mix_scenes)
    picks = [chosen[i % len(chosen)] for i in range(num_copies)]
    q, u, tau, brake = (np.array([getattr(s, name) for s in picks], dtype=float)
                        for name in ("q", "u", "tau", "brake"))
    return q, u, tau, brake.reshape(num_copies, case.model.NUM_BRAKES)


class Copies:
    """N copies of one stepper's state with preallocated ``step_batch`` arguments.

    ``reset`` goes back to the initial states, and the warm-start impulses of spatial contacts
    to zero or (``warm_start``) to those of one step from the initial states. A call resets and
    advances ``num_substeps`` steps.
    """

    def __init__(self, stepper: MoreauJeanStepper, q0: np.ndarray | None = None,
                 u0: np.ndarray | None = None, tau: np.ndarray | None = None,
                 brake: np.ndarray | None = None, num_substeps: int = 1,
                 warm_start: bool = False) -> None:
        """N copies from states q0, u0 (N, n) [SI], inputs tau (N, m), brake bounds (N, k).

        Default: one copy at rest at the origin, zero inputs and bounds.
        """
        self.stepper, self.num_substeps = stepper, num_substeps
        self.q0 = np.zeros((1, stepper.num_dofs)) if q0 is None else np.array(q0, dtype=float)
        self.u0 = np.zeros_like(self.q0) if u0 is None else np.array(u0, dtype=float)
        n = self.q0.shape[0]
        self.q, self.u = self.q0.copy(), self.u0.copy()
        self.tau = np.zeros((n, stepper.num_inputs)) if tau is None else np.array(tau, dtype=float)
        self.brake = np.zeros((n, stepper.num_brakes)) if brake is None else np.array(brake)
        self.impulses0 = np.zeros((n, stepper.num_impulses))
        if warm_start:  # those of one step from (copies of) the initial states
            q, u = self.q0.copy(), self.u0.copy()
            self.impulses0 = stepper.step_batch(q, u, self.tau, self.brake)[0]
        self.out = (self.impulses0.copy(), np.empty((n, stepper.info_size)))

    def reset(self) -> None:
        """Back to the initial states and warm-start impulses."""
        self.q[:] = self.q0
        self.u[:] = self.u0
        self.out[0][:] = self.impulses0

    def advance(self, steps: int) -> None:
        """``steps`` steps in one compiled call (no input checks)."""
        self.stepper.step_batch(self.q, self.u, self.tau, self.brake, steps, check_inputs=False,
                                out=self.out)

    def state(self, copy: int = 0) -> np.ndarray:
        """(q, u) of one copy, concatenated (2n,)."""
        return np.concatenate([self.q[copy], self.u[copy]])

    def run(self, phases: Sequence[tuple[int, Sequence[float], Sequence[float]]],
            stride: int | None = None) -> np.ndarray:
        """From the initial states through (steps, inputs, brake bounds) phases.

        One call per phase, returning copy 0's final (q, u) (2n,); with ``stride``, one call per
        ``stride`` steps, returning every copy's (q, u) at the start and after each (S, N, 2n).
        """
        self.reset()
        self.worst_status = 0
        samples = [np.hstack([self.q, self.u])]
        for steps, tau, brake in phases:  # every copy's inputs (m,), brake bounds (k,)
            self.tau[:] = tau
            if self.brake.shape[1]:
                self.brake[:] = brake
            for chunk in [steps] if stride is None else [stride] * (steps // stride):
                self.advance(chunk)
                if stride is not None:
                    samples.append(np.hstack([self.q, self.u]))
            self.worst_status = max(self.worst_status, int(self.out[1][0, INFO_STATUS]))
        return self.state() if stride is None else np.array(samples)

    def __call__(self) -> None:
        """Restart from the initial states and advance ``num_substeps`` steps."""
        self.reset()
        self.advance(self.num_substeps)


def calibrate_substeps(make: Callable[[int], Callable[[], Any]], target_s: float,
                       max_substeps: int = 10**7) -> int:
    """About the smallest number of substeps for which one call lasts ``target_s``."""
    substeps, seconds = 1, 0.0
    for _ in range(40):
        seconds = timed_call(make(substeps))[1]
        if seconds >= 0.25 * target_s or substeps >= max_substeps:
            break
        substeps = min(max_substeps,
                       substeps * max(2, min(1000, int(0.3 * target_s / max(seconds, 1e-7)))))
    return int(min(max_substeps, max(1, np.ceil(substeps * target_s / max(seconds, 1e-9)))))
