"""Action spaces of torque-driven scenes (with or without a brake) and their batched decoding.

Normalised torques in [-1, 1] are scaled by the scene's bound; the brake is either thresholded
from a Box component ("box"), a Discrete choice ("hybrid") or a continuous Tresca bound
("brake_force"). Out-of-range values are clipped; NaN/inf or wrong shapes raise ValueError.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from numba import njit

from mdi_envs._types import FloatArray

ACTION_MODES = ("box", "hybrid", "brake_force")
_FAST_DTYPES = (np.dtype(np.float32), np.dtype(np.float64))


def torque_brake_space(action_mode: str, num_torques: int, has_brake: bool = True
                       ) -> spaces.Space[Any]:  # fmt: skip
    """The single-copy action space: torques first, then the brake component (if any)."""
    if not has_brake:
        return spaces.Box(-1.0, 1.0, (num_torques,), np.float32)
    if action_mode == "hybrid":
        return spaces.Tuple((spaces.Discrete(2), spaces.Box(-1.0, 1.0, (num_torques,),
                                                            np.float32)))  # fmt: skip
    return spaces.Box(-1.0, 1.0, (num_torques + 1,), np.float32)


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


@njit(cache=True)
def _decode(levels: FloatArray, num_torques: int, brake_rule: int, max_torque: float,
            max_brake_torque: float, tau: FloatArray, brake: FloatArray) -> bool:  # fmt: skip
    """Write tau and brake from normalised levels (N, d); False if any level is not finite.

    brake_rule: 0 no brake column, 1 ideal iff level > 0 ("box"), 2 the Tresca bound
    max_brake_torque (level + 1) / 2 ("brake_force"), 3 ideal iff level == 1 ("hybrid").
    """
    for i in range(levels.shape[0]):
        for j in range(levels.shape[1]):
            if not np.isfinite(levels[i, j]):
                return False
        for j in range(num_torques):
            tau[i, j] = max_torque * min(max(levels[i, j], -1.0), 1.0)
        if brake_rule == 0:
            continue
        level = levels[i, num_torques]
        if brake_rule == 2:
            brake[i, 0] = max_brake_torque * 0.5 * (min(max(level, -1.0), 1.0) + 1.0)
        elif brake_rule == 1:
            brake[i, 0] = np.inf if level > 0.0 else 0.0
        else:
            brake[i, 0] = np.inf if level == 1.0 else 0.0
    return True


def decode_torque_and_brake(
    actions: Any,
    action_mode: str,
    max_torque: float,
    max_brake_torque: float,
    tau: FloatArray,
    brake: FloatArray,
) -> None:
    """Decode a batch of actions into ``tau`` (N, m) [N m] and ``brake`` (N, 0 or 1), in place.

    Torques: the normalised values clipped to [-1, 1] times ``max_torque``. Brake: "box" inf
    (ideal) if its component > 0 else 0 (released); "hybrid" inf for choice 1 else 0;
    "brake_force" the bound max_brake_torque (b + 1) / 2 with b clipped to [-1, 1].

    Raises:
        ValueError: wrong shape, NaN/inf, or a hybrid brake choice other than 0 or 1.
    """
    num_copies, num_torques = tau.shape
    has_brake = brake.shape[1] > 0
    if has_brake and action_mode == "hybrid":
        if not (isinstance(actions, tuple) and len(actions) == 2):
            raise ValueError("a hybrid action is a tuple (brake choice in {0, 1}, torques)")
        choice = _batch_array(actions[0], (num_copies,), "brake choice")
        if not np.isin(choice, (0.0, 1.0)).all():
            raise ValueError(f"brake choice must be 0 or 1, got {choice.tolist()}")
        levels = np.empty((num_copies, num_torques + 1))
        levels[:, :num_torques] = _batch_array(actions[1], (num_copies, num_torques),
                                               "torque action")  # fmt: skip
        levels[:, num_torques] = choice
        rule = 3
    else:
        width = num_torques + (1 if has_brake else 0)
        if (type(actions) is np.ndarray and actions.dtype in _FAST_DTYPES
                and actions.size == num_copies * width
                and actions.shape[-1] == width and actions.ndim <= 2):
            levels = actions.reshape(num_copies, width)  # a view: no conversion, no copy
        else:
            levels = _batch_array(actions, (num_copies, width), "action")
        rule = 0 if not has_brake else (1 if action_mode == "box" else 2)
    if not _decode(levels, num_torques, rule, max_torque, max_brake_torque, tau, brake):
        raise ValueError(f"action contains NaN or inf entries: {levels.tolist()}")


__all__ = ["ACTION_MODES", "decode_torque_and_brake", "torque_brake_space"]
