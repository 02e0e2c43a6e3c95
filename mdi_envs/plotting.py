"""Matplotlib figures for results people look at (saved as PNG; matplotlib is imported lazily)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as error:  # pragma: no cover - depends on the installed extras
        raise ImportError(
            "plots need matplotlib: pip install 'mdi-envs[render]'"
        ) from error
    return plt


def plot_complementarity(z: FloatArray, w: FloatArray, title: str, path: str | Path) -> Path:
    """Bar chart of a solution pair: z (n,) up, w (n,) down, so z_i w_i = 0 is visible.

    Returns:
        The path of the written PNG.
    """
    plt = _pyplot()
    index = np.arange(z.shape[0])
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.bar(index, z, color="tab:blue", label="z (impulse-like unknown)")
    ax.bar(index, -w, color="tab:orange", label="-w (slack: w = M z + q)")
    ax.axhline(0.0, color="black", linewidth=0.8)
    ax.set_xlabel("complementarity pair i")
    ax.set_title(title)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_time_vs_size(
    series: Mapping[str, tuple[Sequence[int], Sequence[float]]],
    title: str,
    path: str | Path,
    ylabel: str = "time per solve [s]",
) -> Path:
    """Log-log plot of one line per method: ``series[name] = (sizes, values)``.

    Returns:
        The path of the written PNG.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, (sizes, values) in series.items():
        ax.loglog(sizes, values, marker="o", label=name)
    ax.set_xlabel("problem size n")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


__all__ = ["plot_complementarity", "plot_time_vs_size"]
