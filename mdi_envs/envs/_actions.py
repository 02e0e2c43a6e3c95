"""Action spaces of torque-driven scenes (with or without a brake) and their batched decoding.

Normalised torques in [-1, 1] are scaled by the scene's bound; the brake is either thresholded
from a Box component ("box"), a Discrete choice ("hybrid") or a continuous Tresca bound
("brake_force"). Out-of-range values are clipped; NaN/inf or wrong shapes raise ValueError.

Decoding is split in two so that an env step costs one compiled call: an array of a dtype in
``ARRAY_DTYPE_CHARS`` whose last axis is ``array_tail`` goes to the env's step kernel as it is
(which checks its size and rank), anything else through ``TorqueBrakeActions.levels``, which
checks the action's type and shape in Python and returns the normalised levels (N, width);
``decode_levels``, compiled and called first inside the kernel, checks them for NaN/inf and
writes the torques and brake bounds.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from gymnasium import spaces
from numba import njit

from mdi_envs._types import FloatArray

ACTION_MODES = ("box", "hybrid", "brake_force")
ARRAY_DTYPE_CHARS = "fd"
"""dtype characters (float32, float64) of action arrays the env kernel takes as they are."""
RULE_NO_BRAKE, RULE_BOX, RULE_BRAKE_FORCE, RULE_HYBRID = 0, 1, 2, 3
"""How ``decode_levels`` reads the brake level (see ``TorqueBrakeActions.rule``)."""


def _batch_array(value: Any, shape: tuple[int, ...], name: str) -> FloatArray:
    """``value`` as a float64 array of ``shape`` (a flat action is accepted for one copy)."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be numeric, got {value!r}") from error
    if array.shape != shape:
        if shape[0] == 1 and array.size == int(np.prod(shape)):
            return array.reshape(shape)
        expected = shape[1:] if shape[0] == 1 else shape
        raise ValueError(f"{name} must have shape {expected}, got {array.shape}")
    return array


@dataclass(frozen=True)
class TorqueBrakeActions:
    """A scene's action coding: ``num_torques`` normalised torques, then an optional brake.

    Attributes:
        mode: "box" (brake engaged, ideal, iff its Box component > 0), "hybrid" (a Discrete
            brake choice with a Box of torques) or "brake_force" (the Tresca bound
            max_brake_torque (b + 1) / 2 from the Box component b). Without a brake: "box".
        num_torques: torque (or force) inputs m.
        has_brake: whether the scene has a brake (one).
        max_torque: bound of every input [N m or N]: a normalised level 1 gives this.
        max_brake_torque: the Tresca bound at level 1 of "brake_force" [N m].
    """

    mode: str
    num_torques: int
    has_brake: bool
    max_torque: float
    max_brake_torque: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in ACTION_MODES:
            raise ValueError(f"action_mode must be one of {ACTION_MODES}, got {self.mode!r}")
        if self.mode != "box" and not self.has_brake:
            raise ValueError(f"action_mode {self.mode!r} needs a scene with a brake")

    @property
    def width(self) -> int:
        """Entries of one copy's normalised levels: the torques, then the brake (if any)."""
        return self.num_torques + (1 if self.has_brake else 0)

    @cached_property
    def array_tail(self) -> tuple[int, ...] | None:
        """``(width,)``: an action array with this last axis holds the levels themselves.

        None in "hybrid" mode, whose actions are tuples.
        """
        return None if self.mode == "hybrid" else (self.width,)

    @property
    def rule(self) -> int:
        """The ``RULE_*`` code of ``decode_levels`` for this mode."""
        if not self.has_brake:
            return RULE_NO_BRAKE
        return {"box": RULE_BOX, "brake_force": RULE_BRAKE_FORCE, "hybrid": RULE_HYBRID}[
            self.mode]

    def space(self) -> spaces.Space[Any]:
        """The single-copy action space: torques first, then the brake component (if any)."""
        torques = spaces.Box(-1.0, 1.0, (self.num_torques,), np.float32)
        if self.mode == "hybrid":
            return spaces.Tuple((spaces.Discrete(2), torques))
        return spaces.Box(-1.0, 1.0, (self.width,), np.float32)

    def levels(self, actions: Any, num_copies: int) -> np.ndarray:
        """A batch of actions as float64 normalised levels, (num_copies, width).

        A flat action is accepted for one copy. NaN/inf are left for ``decode_levels`` to find.

        Raises:
            ValueError: wrong shape, a non-numeric action, or a hybrid brake choice other
                than 0 or 1.
        """
        if self.mode == "hybrid":
            if not (isinstance(actions, tuple) and len(actions) == 2):
                raise ValueError("a hybrid action is a tuple (brake choice in {0, 1}, torques)")
            choice = _batch_array(actions[0], (num_copies,), "brake choice")
            if not np.isin(choice, (0.0, 1.0)).all():
                raise ValueError(f"brake choice must be 0 or 1, got {choice.tolist()}")
            levels = np.empty((num_copies, self.width))
            levels[:, : self.num_torques] = _batch_array(
                actions[1], (num_copies, self.num_torques), "torque action")
            levels[:, self.num_torques] = choice
            return levels
        return _batch_array(actions, (num_copies, self.width), "action")


@njit(inline="always")
def decode_levels(levels: Any, num_torques: int, rule: int, max_torque: float,
                  max_brake_torque: float, tau: FloatArray, brake: FloatArray) -> bool:  # fmt: skip
    """Write tau (N, m) and brake (N, 1 or 0) from normalised levels (N, m + 1 or m), in place.

    ``levels`` may also be flat, (N * width,). Returns False, writing nothing, if any level is
    NaN/inf. Torques: clip(level, -1, 1) max_torque. Brake by ``rule``: RULE_BOX inf (ideal)
    iff level > 0 else 0 (released); RULE_BRAKE_FORCE the Tresca bound max_brake_torque
    (clip(level, -1, 1) + 1) / 2; RULE_HYBRID inf iff level == 1 else 0.
    """
    flat = levels.ravel()
    for value in flat:
        if not np.isfinite(value):
            return False
    width = flat.size // tau.shape[0]
    for i in range(tau.shape[0]):
        for j in range(num_torques):
            tau[i, j] = max_torque * min(max(flat[i * width + j], -1.0), 1.0)
        if rule == RULE_NO_BRAKE:
            continue
        level = flat[i * width + num_torques]
        if rule == RULE_BRAKE_FORCE:
            brake[i, 0] = max_brake_torque * 0.5 * (min(max(level, -1.0), 1.0) + 1.0)
        elif rule == RULE_BOX:
            brake[i, 0] = np.inf if level > 0.0 else 0.0
        else:
            brake[i, 0] = np.inf if level == 1.0 else 0.0
    return True


__all__ = ["ACTION_MODES", "ARRAY_DTYPE_CHARS", "TorqueBrakeActions", "decode_levels"]
