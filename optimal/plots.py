"""Pictures of a reference like the paper's: Figs. 3-4 (manipulator) and 7-9 (robot).

``plot_reference(reference, directory)`` writes PNGs and returns their paths. Needs matplotlib
(``pip install 'mdi-envs[render]'``), imported here only, with the non-interactive Agg backend.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from optimal.references import Reference

SLIDING_SPEED = 1e-6
"""[m/s] a wheel counts as sliding above this slip speed (as ``optimal.mode_search.SLIP_TOLERANCE``
with the robot's 1 m/s velocity unit)."""


def plot_reference(reference: Reference, directory: Path | str) -> list[Path]:
    """Save the reference's figures into ``directory``; returns the PNG paths."""
    import matplotlib

    matplotlib.use("Agg")
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    if reference.brake_bound is not None:
        return _manipulator(reference, folder)
    if "mode" in reference.arrays:
        return _robot(reference, folder)
    return []


def plot_search(reference: Reference, directory: Path | str) -> Path:
    """The global search and refinement of a searched reference (``metadata["search"]``).

    Left: the best cost after each start (does the search saturate?) with every start's
    continuation optimum and its optimum after the mode-neighbourhood search. Right: the
    cost against N over the refinement levels. Saved as ``NAME_search.png``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meta = reference.metadata
    search, refinement = meta["search"], meta["refinement"]
    unit = "s" if meta["cost_kind"] == "time" else "N² m² s"
    label = "t_f" if meta["cost_kind"] == "time" else "effort"
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), width_ratios=(2, 1))
    starts = np.arange(1, search["starts"] + 1)
    per_start = search["per_start"]
    nan = float("nan")
    left.scatter(starts, [nan if r["continuation_cost"] is None else r["continuation_cost"]
                          for r in per_start], marker="x", color="0.6",
                 label="continuation optimum")
    left.scatter(starts, [nan if r["local_cost"] is None else r["local_cost"]
                          for r in per_start], marker="o", facecolors="none",
                 edgecolors="C0", label="after the mode search")
    left.step(starts, search["running_best"], where="post", color="C3", label="best so far")
    finite = [c for r in per_start for c in (r["continuation_cost"], r["local_cost"])
              if c is not None and np.isfinite(c)]
    if finite:
        low = min(finite)
        left.set_ylim(low * 0.99, min(max(finite), 2.0 * low) * 1.01)
    left.set_xlabel("start (completion order)")
    left.set_ylabel(f"{label} [{unit}]")
    left.set_title(f"{reference.name}: {search['starts']} starts, {search['solves']} "
                   f"fixed-pattern solves, {search['wall_time'] / 60:.0f} min")
    left.legend(fontsize=8)
    levels = refinement["levels"]
    right.plot([lv["num_intervals"] for lv in levels], [lv["cost"] for lv in levels], "o-")
    shipped = levels[meta["shipped_level"]]
    right.plot([shipped["num_intervals"]], [shipped["cost"]], "r*", markersize=12,
               label="shipped")
    right.set_xscale("log", base=2)
    right.set_xticks([lv["num_intervals"] for lv in levels],
                     [str(lv["num_intervals"]) for lv in levels])
    right.minorticks_off()
    right.set_xlabel("N (intervals)")
    right.set_ylabel(f"{label} [{unit}]")
    right.set_title("mesh refinement")
    right.legend(fontsize=8)
    fig.tight_layout()
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{reference.name}_search.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _manipulator(reference: Reference, folder: Path) -> list[Path]:
    """Fig. 3 (velocities, positions) and Fig. 4 (torque, brake impulses)."""
    import matplotlib.pyplot as plt

    t, q, u = reference.time, reference.q, reference.u
    brake = reference.brake_bound
    if brake is None:
        raise ValueError(f"{reference.name} has no brake: not a manipulator reference")
    engaged = np.isinf(brake[:, 0])
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(t, u[:, 0], label="alpha'")
    axes[0].plot(t, u[:, 1], label="beta'")
    axes[0].plot(t, u[:, 1] - u[:, 0], "--", label="beta' - alpha'")
    axes[0].set_ylabel("velocity [rad/s]")
    axes[1].plot(t, q[:, 0], label="alpha")
    axes[1].plot(t, q[:, 1], label="beta")
    axes[1].set_ylabel("position [rad]")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.fill_between(t[:-1], 0, 1, where=engaged, step="post", alpha=0.12, color="k",
                        transform=ax.get_xaxis_transform(), label="brake engaged")
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{reference.name}: t_f = {reference.final_time:.3f} s (cf. paper Fig. 3)")
    first = folder / f"{reference.name}_states.png"
    fig.savefig(first, dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    axes[0].step(t[:-1], reference.tau[:, 0], where="post")
    axes[0].set_ylabel("motor torque [N m]")
    impulses = reference.arrays["brake_impulse"][:, 0]
    axes[1].stem(t[1:], impulses, basefmt=" ")
    axes[1].set_ylabel("brake impulse P_B [N m s]")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{reference.name}: controls (cf. paper Fig. 4)")
    second = folder / f"{reference.name}_controls.png"
    fig.savefig(second, dpi=110)
    plt.close(fig)
    return [first, second]


def _robot(reference: Reference, folder: Path) -> list[Path]:
    """Figs. 7/8 (path coloured by mode) and Fig. 9 (contact forces, slip speeds)."""
    import matplotlib.pyplot as plt

    t, q, h = reference.time, reference.q, reference.time_step
    modes = reference.arrays["mode"]
    sliding = reference.arrays["slip_speed"][:, :2] > SLIDING_SPEED
    fig, ax = plt.subplots(figsize=(5, 6))
    classes = {
        "2-DOF mode (both wheels roll)": (modes == 2, "tab:green"),
        "3L-DOF mode (left wheel slides)": ((modes == 3) & sliding[:, 0], "tab:orange"),
        "3R-DOF mode (right wheel slides)": ((modes == 3) & sliding[:, 1], "tab:purple"),
        "5-DOF mode (both slide)": (modes == 5, "tab:red"),
    }
    for label, (chosen, colour) in classes.items():
        if np.any(chosen):
            index = np.flatnonzero(chosen) + 1
            ax.scatter(q[index, 0], q[index, 1], s=8, color=colour, label=label)
    every = max(1, len(q) // 20)
    ax.quiver(q[::every, 0], q[::every, 1], np.cos(q[::every, 2]), np.sin(q[::every, 2]),
              angles="xy", scale=12, width=0.004, color="0.3", label="heading")
    ax.plot(q[:, 0], q[:, 1], color="0.6", lw=0.8, zorder=0)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2)
    ax.grid(alpha=0.3)
    ax.set_title(f"{reference.name}: t_f = {reference.final_time:.2f} s (cf. Figs. 7-8)")
    first = folder / f"{reference.name}_path.png"
    fig.savefig(first, dpi=110, bbox_inches="tight")
    plt.close(fig)

    fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
    normal = reference.arrays["normal_impulse"] / h
    tangent = reference.arrays["tangent_impulse"] / h
    slip = reference.arrays["slip_speed"]
    for i, label in enumerate(("N_L", "N_R", "N_stick")):
        axes[0, 0].plot(t[1:], normal[:, i], label=label)
    axes[0, 0].set_ylabel("normal force [N]")
    for i, label in enumerate(("v_L", "v_R", "v_stick")):
        axes[0, 1].plot(t[1:], slip[:, i], label=label)
    axes[0, 1].set_ylabel("slip speed [m/s]")
    axes[1, 0].plot(t[1:], tangent[:, 0], label="F_Lx")
    axes[1, 0].plot(t[1:], tangent[:, 1], label="F_Ly")
    axes[1, 0].set_ylabel("left wheel friction [N]")
    axes[1, 1].plot(t[1:], tangent[:, 2], label="F_Rx")
    axes[1, 1].plot(t[1:], tangent[:, 3], label="F_Ry")
    axes[1, 1].set_ylabel("right wheel friction [N]")
    for ax in axes.ravel():
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time [s]")
    fig.suptitle(f"{reference.name}: contact forces and slip (cf. paper Fig. 9)")
    second = folder / f"{reference.name}_contacts.png"
    fig.savefig(second, dpi=110)
    plt.close(fig)
    return [first, second]


__all__ = ["plot_reference"]
