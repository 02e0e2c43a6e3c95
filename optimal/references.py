"""Reference trajectories shipped with the package: one ``NAME.npz`` (arrays) + ``NAME.json``.

``load_reference(name)`` needs numpy and json only -- not CasADi -- so that baselines and tests
can compare against the optimum anywhere. Arrays (N intervals, n coordinates, m inputs):

* ``time`` (N+1,) [s], ``q`` (N+1, n), ``u`` (N+1, n): the optimal trajectory on the grid;
* ``tau`` (N, m): inputs held constant over each interval [N m];
* ``brake_bound`` (N, k): the brake command per interval for ``MoreauJeanStepper.step``
  (0 released, inf engaged), for models with brakes; ``brake_impulse`` (N, k) [N m s];
* ``normal_impulse`` (N, c), ``tangent_impulse`` (N, 2c) [N s], ``slip_speed`` (N, c) [m/s],
  ``mode`` (N,): the robot's contact impulses, slip speeds and Table 1 mode after each step.

The metadata (JSON) holds env id and version, model and parameters, time step, N, t_f, cost,
the continuation history (penalty, relaxation, complementarity residual and solve time per
stage), the replay errors and the commit the reference was computed at.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray

REFERENCE_DIR = Path(__file__).parent / "references"
"""Where the shipped references live (package data)."""


@dataclass(frozen=True)
class Reference:
    """One reference solution.

    Attributes:
        name: the problem's name. arrays: see the module docstring. metadata: see there.
    """

    name: str
    arrays: dict[str, np.ndarray] = field(repr=False)
    metadata: dict[str, Any] = field(repr=False)

    @property
    def time(self) -> FloatArray:
        """(N+1,) grid times [s]."""
        return self.arrays["time"]

    @property
    def q(self) -> FloatArray:
        """(N+1, n) coordinates."""
        return self.arrays["q"]

    @property
    def u(self) -> FloatArray:
        """(N+1, n) velocities."""
        return self.arrays["u"]

    @property
    def tau(self) -> FloatArray:
        """(N, m) inputs, held over each interval."""
        return self.arrays["tau"]

    @property
    def brake_bound(self) -> FloatArray | None:
        """(N, k) brake commands (0 released, inf engaged), or None without brakes."""
        return self.arrays.get("brake_bound")

    @property
    def time_step(self) -> float:
        """H = t_f / N [s]."""
        return float(self.metadata["time_step"])

    @property
    def final_time(self) -> float:
        """t_f [s]."""
        return float(self.metadata["final_time"])

    @property
    def cost(self) -> float:
        """The optimal cost (t_f [s] or effort [N^2 m^2 s])."""
        return float(self.metadata["cost"])


def save_reference(reference: Reference, directory: Path | str = REFERENCE_DIR) -> Path:
    """Write ``NAME.npz`` and ``NAME.json`` into ``directory``; returns the JSON path."""
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(folder / f"{reference.name}.npz", **reference.arrays)  # type: ignore[arg-type]
    path = folder / f"{reference.name}.json"
    path.write_text(json.dumps(reference.metadata, indent=1, sort_keys=True) + "\n")
    return path


def load_reference(name: str, directory: Path | str = REFERENCE_DIR) -> Reference:
    """Read the reference ``name`` (numpy and json only).

    Raises:
        FileNotFoundError: no such reference in ``directory`` (the message lists those there).
    """
    folder = Path(directory)
    arrays_path, metadata_path = folder / f"{name}.npz", folder / f"{name}.json"
    if not (arrays_path.exists() and metadata_path.exists()):
        known = sorted(path.stem for path in folder.glob("*.json"))
        raise FileNotFoundError(
            f"no reference {name!r} in {folder}; available: {', '.join(known) or 'none'}"
        )
    with np.load(arrays_path) as data:
        arrays = {key: data[key] for key in data.files}
    return Reference(name, arrays, json.loads(metadata_path.read_text()))


def available_references(directory: Path | str = REFERENCE_DIR) -> list[str]:
    """Names of the references stored in ``directory``."""
    return sorted(path.stem for path in Path(directory).glob("*.json"))


__all__ = ["REFERENCE_DIR", "Reference", "available_references", "load_reference",
           "save_reference"]
