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


def plot_manipulator_rollout(
    t: FloatArray,
    q: FloatArray,
    u: FloatArray,
    brake_impulse: FloatArray,
    reference: tuple[FloatArray, FloatArray, FloatArray],
    title: str,
    path: str | Path,
) -> Path:
    """Paper-style figure (Yunt & Glocker, Figs. 3-4) of a manipulator rollout.

    Args:
        t: (T,) times [s]. q: (T, 2) angles alpha, beta [rad]. u: (T, 2) rates [rad/s].
        brake_impulse: (T,) brake impulse per step [N m s].
        reference: (t_ref, q_ref, u_ref) of a reference solution, drawn dashed.
        title: figure title. path: PNG file.

    Returns:
        The path of the written PNG.
    """
    plt = _pyplot()
    t_ref, q_ref, u_ref = reference
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for j, name in enumerate(("alpha", "beta")):
        axes[0].plot(t, q[:, j], label=f"{name} (time-stepping)")
        axes[0].plot(t_ref, q_ref[:, j], "k--", linewidth=0.8)
        axes[1].plot(t, u[:, j], label=f"{name}' (time-stepping)")
        axes[1].plot(t_ref, u_ref[:, j], "k--", linewidth=0.8)
    axes[0].set_ylabel("angle [rad]")
    axes[1].set_ylabel("rate [rad/s]")
    axes[2].plot(t, brake_impulse, color="tab:red")
    axes[2].set_ylabel("brake impulse [N m s]")
    axes[2].set_xlabel("time [s]")
    axes[0].legend(fontsize=8, title="dashed: event-driven reference", title_fontsize=8)
    axes[1].legend(fontsize=8)
    axes[0].set_title(title)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


__all__ = ["plot_complementarity", "plot_manipulator_rollout", "plot_time_vs_size"]
