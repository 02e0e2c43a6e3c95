"""Pygame pictures of the systems, the window or pixel array they go to, and saved animations.

One ``draw_*`` function per system returns a canvas (a ``pygame.Surface``) of one state, drawn
in world coordinates [m] with the y axis up and anti-aliased with ``pygame.gfxdraw``, as
Gymnasium's classic-control renderers do (draw y-up, flip the canvas once at the end). A
``Viewer`` shows canvases in a window (render mode "human") or returns them as (H, W, 3) uint8
arrays ("rgb_array"); ``save_animation`` writes such arrays to a GIF or an MP4. Pygame is imported
only inside the functions that need it: ``pip install 'mdi-envs[render]'``.
"""

from __future__ import annotations

import math
import os
import pathlib
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from mdi_envs._types import FloatArray
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER

if TYPE_CHECKING:
    import pygame

    from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulatorParameters
    from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters
    from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters
    from mdi_envs.mechanics.models.sliding_block import SlidingBlockParameters

Color = tuple[int, int, int]
Point = tuple[float, float]

# Palette (Tango): one meaning per colour across all scenes.
BACKGROUND: Color = (255, 255, 255)
GRID: Color = (236, 238, 240)
AXIS: Color = (205, 208, 212)
INK: Color = (46, 52, 54)
GHOST: Color = (214, 220, 228)
GHOST_EDGE: Color = (170, 180, 194)
LINK_1: Color = (52, 101, 164)
LINK_2: Color = (114, 159, 207)
BRAKE_ENGAGED: Color = (204, 0, 0)
BRAKE_RELEASED: Color = (186, 189, 182)
TORQUE: Color = (245, 121, 0)
ROLLING: Color = (78, 154, 6)
SLIPPING: Color = (245, 121, 0)
WHEEL: Color = (85, 87, 83)
FORCE: Color = (117, 80, 123)
TRAIL: Color = (52, 101, 164)
GOAL: Color = (78, 154, 6)
BALL: Color = (204, 77, 77)
BALL_HIGHLIGHT: Color = (239, 160, 160)
GROUND: Color = (211, 215, 207)
BLOCK: Color = (233, 185, 110)
BLOCK_EDGE: Color = (143, 89, 2)

# View extents (rendering choices, not model constants).
MANIPULATOR_VIEW_MARGIN = 0.15  # [-] free space around the reach l1 + l2, as a fraction of it
DIFF_DRIVE_VIEW_MARGIN = 1.0  # [m] around the start and goal positions
DIFF_DRIVE_FORCE_LENGTH = 1.0  # [m] arrow length of a wheel's Coulomb limit mu m g / 2
DIFF_DRIVE_MAX_ARROW = 1.5  # [m] longest force arrow
BALL_VIEW_HEIGHT = 1.2  # [m] default height shown above the ground
SLOPE_VIEW_WIDTH = 4.0  # [m] default width of world shown around the block

RENDER_FPS = 50  # [1/s] default frame rate of a "human" window


def _import_pygame() -> Any:
    """The pygame module (with ``gfxdraw`` loaded), or an ImportError saying what to install."""
    try:
        import pygame
        import pygame.gfxdraw  # noqa: F401 - loads the submodule used as pygame.gfxdraw
    except ImportError as error:  # pragma: no cover - depends on the installed extras
        raise ImportError("rendering needs pygame: pip install 'mdi-envs[render]'") from error
    return pygame


def _state(q: ArrayLike, names: Sequence[str], what: str = "q") -> FloatArray:
    """``q`` as a finite float array of shape (len(names),), else a ValueError naming the shape."""
    array = np.asarray(q, dtype=np.float64)
    expected = (len(names),)
    if array.shape != expected:
        raise ValueError(
            f"{what} must have shape {expected} ({', '.join(names)}), got shape {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{what} must be finite, got {array}")
    return array


def _check_size(size: tuple[int, int]) -> tuple[int, int]:
    width, height = (int(size[0]), int(size[1]))
    if width <= 0 or height <= 0:
        raise ValueError(f"size must be two positive pixel counts (width, height), got {size}")
    return width, height


def _nice_spacing(span: float) -> float:
    """A 1-2-5 x 10^k spacing [m] giving about eight ticks over ``span`` [m]."""
    raw = span / 8.0
    power = 10.0 ** math.floor(math.log10(raw))
    for step in (1.0, 2.0, 5.0, 10.0):
        if raw <= step * power:
            return step * power
    return 10.0 * power  # pragma: no cover - the loop always returns


def _rotate(point: Point, angle: float) -> Point:
    c, s = math.cos(angle), math.sin(angle)
    return (c * point[0] - s * point[1], s * point[0] + c * point[1])


def _pose(state: FloatArray) -> tuple[float, float, float]:
    """The planar pose (x [m], y [m], phi [rad]) from the first three entries of a state."""
    return (float(state[0]), float(state[1]), float(state[2]))


def _place(pose: tuple[float, float, float], points: Sequence[Point]) -> list[Point]:
    """Body-frame points [m] moved to the planar pose (x [m], y [m], phi [rad])."""
    x, y, phi = pose
    placed = []
    for point in points:
        rx, ry = _rotate(point, phi)
        placed.append((x + rx, y + ry))
    return placed


class _View:
    """World box [m] fitted into a canvas, aspect kept, centred; pixel y grows upward.

    The canvas is drawn y-up and flipped once at the end (``_Painter.finish``), as Gymnasium's
    classic-control renderers do.
    """

    def __init__(self, x_range: Point, y_range: Point, size: tuple[int, int]) -> None:
        width, height = size
        span_x, span_y = x_range[1] - x_range[0], y_range[1] - y_range[0]
        self.scale = min(width / span_x, height / span_y)  # [px/m]
        center_x, center_y = 0.5 * (x_range[0] + x_range[1]), 0.5 * (y_range[0] + y_range[1])
        self.offset = (0.5 * width - self.scale * center_x, 0.5 * height - self.scale * center_y)
        half_x, half_y = 0.5 * width / self.scale, 0.5 * height / self.scale
        # The world box actually visible (wider than asked along one axis when aspects differ).
        self.x_range = (center_x - half_x, center_x + half_x)
        self.y_range = (center_y - half_y, center_y + half_y)

    def px(self, point: Point) -> tuple[int, int]:
        """Pixel (column, row-from-bottom) of a world point [m]."""
        return (
            int(round(self.offset[0] + self.scale * point[0])),
            int(round(self.offset[1] + self.scale * point[1])),
        )

    def length(self, meters: float) -> int:
        """Pixels spanned by a world length [m], at least 1."""
        return max(1, int(round(self.scale * meters)))


class _Painter:
    """Anti-aliased drawing in world coordinates [m] on one canvas (widths in [m] unless noted)."""

    def __init__(self, view: _View, size: tuple[int, int], background: Color) -> None:
        self.pygame = _import_pygame()
        self.gfxdraw = self.pygame.gfxdraw
        self.view = view
        self.surface = self.pygame.Surface(size)
        self.surface.fill(background)

    def finish(self) -> pygame.Surface:
        """The canvas flipped so that world y points up on screen."""
        flipped: pygame.Surface = self.pygame.transform.flip(self.surface, False, True)
        return flipped

    def polygon(
        self, points: Sequence[Point], fill: Color | None, edge: Color | None = None
    ) -> None:
        pixels = [self.view.px(point) for point in points]
        if fill is not None:
            self.gfxdraw.aapolygon(self.surface, pixels, fill)
            self.gfxdraw.filled_polygon(self.surface, pixels, fill)
        if edge is not None:
            self.gfxdraw.aapolygon(self.surface, pixels, edge)

    def disc(self, center: Point, radius: float, fill: Color, edge: Color | None = None) -> None:
        cx, cy = self.view.px(center)
        r = self.view.length(radius)
        self.gfxdraw.aacircle(self.surface, cx, cy, r, fill)
        self.gfxdraw.filled_circle(self.surface, cx, cy, r, fill)
        if edge is not None:
            self.gfxdraw.aacircle(self.surface, cx, cy, r, edge)

    def ring(self, center: Point, radius: float, color: Color, width_px: int = 1) -> None:
        cx, cy = self.view.px(center)
        r = self.view.length(radius)
        if width_px > 1:
            self.pygame.draw.circle(self.surface, color, (cx, cy), r, width_px)
            self.gfxdraw.aacircle(self.surface, cx, cy, max(1, r - width_px + 1), color)
        self.gfxdraw.aacircle(self.surface, cx, cy, r, color)

    def rod(self, start: Point, end: Point, width: float, color: Color) -> None:
        """A bar of ``width`` [m] with round ends."""
        self.segment(start, end, width, color)
        self.disc(start, 0.5 * width, color)
        self.disc(end, 0.5 * width, color)

    def segment(self, start: Point, end: Point, width: float, color: Color) -> None:
        """A bar of ``width`` [m] with square ends."""
        dx, dy = end[0] - start[0], end[1] - start[1]
        norm = math.hypot(dx, dy)
        if norm == 0.0:
            return
        ox, oy = -0.5 * width * dy / norm, 0.5 * width * dx / norm
        self.polygon(
            [(start[0] + ox, start[1] + oy), (end[0] + ox, end[1] + oy),
             (end[0] - ox, end[1] - oy), (start[0] - ox, start[1] - oy)],
            color,
        )

    def hairline(self, start: Point, end: Point, color: Color) -> None:
        """A one-pixel anti-aliased line."""
        self.pygame.draw.aaline(self.surface, color, self.view.px(start), self.view.px(end))

    def dashed(self, start: Point, end: Point, dash: float, width: float, color: Color) -> None:
        """Dashes of length ``dash`` [m] separated by equal gaps."""
        length = math.hypot(end[0] - start[0], end[1] - start[1])
        num_dashes = int(length / (2.0 * dash)) + 1
        for k in range(num_dashes):
            t0, t1 = 2 * k * dash / length, min(1.0, (2 * k + 1) * dash / length)
            self.segment(
                (start[0] + t0 * (end[0] - start[0]), start[1] + t0 * (end[1] - start[1])),
                (start[0] + t1 * (end[0] - start[0]), start[1] + t1 * (end[1] - start[1])),
                width, color,
            )

    def polyline(self, points: Sequence[Point], color: Color, width_px: int = 2) -> None:
        pixels = [self.view.px(point) for point in points]
        self.pygame.draw.lines(self.surface, color, False, pixels, width_px)
        self.pygame.draw.aalines(self.surface, color, False, pixels)

    def arrow(self, tail: Point, head: Point, width: float, color: Color) -> None:
        """Shaft of ``width`` [m] and a head 3 widths wide, at most half the arrow long."""
        dx, dy = head[0] - tail[0], head[1] - tail[1]
        length = math.hypot(dx, dy)
        if length == 0.0:
            return
        ux, uy = dx / length, dy / length
        head_length = min(3.0 * width, 0.5 * length)
        base = (head[0] - head_length * ux, head[1] - head_length * uy)
        self.segment(tail, base, width, color)
        self._head(head, (ux, uy), head_length, 1.5 * width, color)

    def arc_arrow(
        self, center: Point, radius: float, start: float, stop: float, width: float, color: Color
    ) -> None:
        """A circular arrow from angle ``start`` to ``stop`` [rad] (either sense), head at stop."""
        sweep = stop - start
        if sweep == 0.0:
            return
        sense = math.copysign(1.0, sweep)
        head_length = 3.0 * width
        body_stop = stop - sense * min(head_length / radius, 0.5 * abs(sweep))
        num = max(2, int(abs(body_stop - start) / 0.05) + 2)
        angles = np.linspace(start, body_stop, num)
        outer = [(center[0] + (radius + 0.5 * width) * math.cos(a),
                  center[1] + (radius + 0.5 * width) * math.sin(a)) for a in angles]
        inner = [(center[0] + (radius - 0.5 * width) * math.cos(a),
                  center[1] + (radius - 0.5 * width) * math.sin(a)) for a in angles[::-1]]
        self.polygon(outer + inner, color)
        tip = (center[0] + radius * math.cos(stop), center[1] + radius * math.sin(stop))
        base = (center[0] + radius * math.cos(body_stop), center[1] + radius * math.sin(body_stop))
        direction = (tip[0] - base[0], tip[1] - base[1])
        norm = math.hypot(*direction)
        self._head(tip, (direction[0] / norm, direction[1] / norm), norm, 1.5 * width, color)

    def _head(
        self, tip: Point, unit: Point, length: float, half_width: float, color: Color
    ) -> None:
        base = (tip[0] - length * unit[0], tip[1] - length * unit[1])
        side = (-unit[1] * half_width, unit[0] * half_width)
        self.polygon(
            [tip, (base[0] + side[0], base[1] + side[1]), (base[0] - side[0], base[1] - side[1])],
            color,
        )

    def grid(self, spacing: float, color: Color, axis_color: Color | None = None) -> None:
        """Lines every ``spacing`` [m] over the visible box; the axes x = 0, y = 0 darker."""
        (x0, x1), (y0, y1) = self.view.x_range, self.view.y_range
        for k in range(math.ceil(x0 / spacing), math.floor(x1 / spacing) + 1):
            line_color = axis_color if (k == 0 and axis_color is not None) else color
            self.hairline((k * spacing, y0), (k * spacing, y1), line_color)
        for k in range(math.ceil(y0 / spacing), math.floor(y1 / spacing) + 1):
            line_color = axis_color if (k == 0 and axis_color is not None) else color
            self.hairline((x0, k * spacing), (x1, k * spacing), line_color)


# --- blockable manipulator ------------------------------------------------------------------


def draw_manipulator(
    q: ArrayLike,
    brake_engaged: bool,
    torque_fraction: float,
    parameters: BlockableManipulatorParameters,
    size: tuple[int, int] = (500, 500),
    goal_q: Sequence[float] | None = MANIPULATOR_MANEUVER.goal_q,
) -> pygame.Surface:
    """Top view of the two-link manipulator, its brake, its motor torque and its goal pose.

    The base is at the centre; link 1 (dark blue) is hinged there and link 2 (light blue) at its
    tip, the elbow. An engaged brake shows as a red clamp around the elbow, a released one as a
    thin grey ring. An orange arc around the base shows the motor torque: counter-clockwise for
    positive tau (increasing alpha), sweeping up to 270 degrees at full torque.

    Args:
        q: (2,) absolute link angles (alpha, beta) [rad], measured from the world x axis.
        brake_engaged: whether the brake on beta - alpha is engaged.
        torque_fraction: motor torque as a fraction of its bound, in [-1, 1] (clipped).
        parameters: the model's parameters; the link lengths [m] set the drawing.
        size: canvas (width, height) [px].
        goal_q: (2,) goal angles [rad] drawn as a faint ghost (default: the maneuver's goal,
            alpha = beta = pi); None draws no ghost.

    Returns:
        The canvas, a ``pygame.Surface`` of ``size``.

    Raises:
        ValueError: if q (or goal_q) is not a finite array of shape (2,), or torque_fraction is
            not finite.
    """
    alpha, beta = _state(q, ("alpha", "beta"))
    if not math.isfinite(torque_fraction):
        raise ValueError(f"torque_fraction must be finite, got {torque_fraction}")
    size = _check_size(size)
    l1, l2 = parameters.link1_length, parameters.link2_length
    reach = l1 + l2
    half = (1.0 + MANIPULATOR_VIEW_MARGIN) * reach
    paint = _Painter(_View((-half, half), (-half, half), size), size, BACKGROUND)
    rod_width, joint_radius = 0.06 * reach, 0.045 * reach
    base: Point = (0.0, 0.0)

    def links(a: float, b: float) -> tuple[Point, Point]:
        elbow = (l1 * math.cos(a), l1 * math.sin(a))
        return elbow, (elbow[0] + l2 * math.cos(b), elbow[1] + l2 * math.sin(b))

    paint.ring(base, reach, GRID, width_px=2)
    if goal_q is not None:
        goal_alpha, goal_beta = _state(goal_q, ("alpha", "beta"), "goal_q")
        ghost_elbow, ghost_tip = links(goal_alpha, goal_beta)
        paint.rod(base, ghost_elbow, rod_width, GHOST)
        paint.rod(ghost_elbow, ghost_tip, rod_width, GHOST)
        paint.ring(ghost_tip, 1.2 * joint_radius, GHOST_EDGE, width_px=2)

    plate = 0.08 * reach
    paint.polygon([(-plate, -plate), (plate, -plate), (plate, plate), (-plate, plate)],
                  BRAKE_RELEASED, INK)

    fraction = float(np.clip(torque_fraction, -1.0, 1.0))
    if abs(fraction) > 1e-3:
        sweep = 1.5 * math.pi * abs(fraction)
        middle = alpha + math.pi  # opposite link 1, so the arc never hides under it
        sense = math.copysign(1.0, fraction)
        paint.arc_arrow(base, 0.17 * reach, middle - 0.5 * sense * sweep,
                        middle + 0.5 * sense * sweep, 0.022 * reach, TORQUE)

    elbow, tip = links(alpha, beta)
    paint.rod(base, elbow, rod_width, LINK_1)
    paint.rod(elbow, tip, rod_width, LINK_2)
    if brake_engaged:
        paint.disc(elbow, 2.0 * joint_radius, BRAKE_ENGAGED, INK)
    else:
        paint.ring(elbow, 2.0 * joint_radius, BRAKE_RELEASED, width_px=2)
    paint.disc(base, joint_radius, INK)
    paint.disc(elbow, joint_radius, INK)
    paint.disc(tip, 0.6 * joint_radius, INK)
    return paint.finish()


# --- differential-drive robot ---------------------------------------------------------------


def _chassis_outline(parameters: DiffDriveParameters) -> list[Point]:
    """Body-frame outline [m]: a box from behind the axle to a nose at the stick."""
    a, b, c = parameters.axle_offset, parameters.half_track, parameters.stick_offset
    r = parameters.wheel_radius
    half_width = b - 0.5 * _wheel_width(parameters) - 0.01 * b
    rear = -a - r
    shoulder = max(rear, c - 0.5 * half_width)
    return [(rear, half_width), (rear, -half_width), (shoulder, -half_width),
            (c, -0.4 * half_width), (c, 0.4 * half_width), (shoulder, half_width)]


def _wheel_width(parameters: DiffDriveParameters) -> float:
    return 0.5 * parameters.wheel_radius


def _contact_points(parameters: DiffDriveParameters) -> list[Point]:
    """Body-frame contacts [m]: left wheel (-a, b), right wheel (-a, -b), stick (c, 0)."""
    a, b, c = parameters.axle_offset, parameters.half_track, parameters.stick_offset
    return [(-a, b), (-a, -b), (c, 0.0)]


def _wheel_outline(parameters: DiffDriveParameters, center: Point) -> list[Point]:
    r, half_width = parameters.wheel_radius, 0.5 * _wheel_width(parameters)
    x, y = center
    return [(x - r, y - half_width), (x + r, y - half_width),
            (x + r, y + half_width), (x - r, y + half_width)]


def _robot(
    paint: _Painter,
    parameters: DiffDriveParameters,
    pose: tuple[float, float, float],
    body: Color,
    edge: Color,
    wheels: Sequence[Color],
) -> None:
    contacts = _contact_points(parameters)
    paint.polygon(_place(pose, _chassis_outline(parameters)), body, edge)
    for contact, color in zip(contacts[:2], wheels, strict=True):
        paint.polygon(_place(pose, _wheel_outline(parameters, contact)), color, edge)


def draw_diff_drive(
    q: ArrayLike,
    parameters: DiffDriveParameters,
    goal_pose: Sequence[float],
    contact_forces: ArrayLike | None = None,
    sliding: ArrayLike | None = None,
    trail: ArrayLike | None = None,
    size: tuple[int, int] = (500, 500),
) -> pygame.Surface:
    """Top view of the differential-drive robot on a 1 m grid, with its goal and its path.

    The frame is fixed: it fits the maneuver's start position and ``goal_pose`` with a 1 m margin
    (for the paper's maneuver, x in [-1, 3] and y in [-1, 6], widened to the canvas aspect), so an
    animation does not jump. The chassis points its nose to the stick (c, 0); the wheels are
    green while rolling and orange while slipping (grey when ``sliding`` is None); the goal pose
    is a faint ghost; the friction forces are purple arrows from the contact points, a wheel's
    Coulomb limit mu m g / 2 drawn 1 m long (capped at 1.5 m).

    Args:
        q: (5,) coordinates (x [m], y [m], phi [rad], psi_L [rad], psi_R [rad]); the wheel
            angles are not drawn.
        parameters: the model's parameters (chassis geometry, wheel radius, friction, mass).
        goal_pose: (3,) goal (x [m], y [m], phi [rad]).
        contact_forces: (3, 2) friction force (F_x, F_y) [N] on the robot at the left wheel,
            right wheel and stick, in the body frame (x forward, y left); None draws none.
        sliding: (3,) per contact (left wheel, right wheel, stick) true while it slips.
        trail: (k, 2) past positions (x, y) [m], drawn as a polyline when k >= 2.
        size: canvas (width, height) [px].

    Returns:
        The canvas, a ``pygame.Surface`` of ``size``.

    Raises:
        ValueError: if an argument does not have the shape stated above or is not finite.
    """
    state = _state(q, ("x", "y", "phi", "psi_L", "psi_R"))
    goal = _state(goal_pose, ("x", "y", "phi"), "goal_pose")
    size = _check_size(size)
    start = DIFF_DRIVE_MANEUVER.initial_pose
    margin = DIFF_DRIVE_VIEW_MARGIN
    x_range = (min(start[0], goal[0]) - margin, max(start[0], goal[0]) + margin)
    y_range = (min(start[1], goal[1]) - margin, max(start[1], goal[1]) + margin)
    paint = _Painter(_View(x_range, y_range, size), size, BACKGROUND)
    paint.grid(1.0, GRID, AXIS)

    if trail is not None:
        path = np.asarray(trail, dtype=np.float64)
        if path.ndim != 2 or path.shape[1] != 2:
            raise ValueError(f"trail must have shape (k, 2) of (x, y), got shape {path.shape}")
        if path.shape[0] >= 2:
            paint.polyline([(float(px), float(py)) for px, py in path], TRAIL)

    marker = parameters.half_track
    paint.ring((float(goal[0]), float(goal[1])), 1.6 * marker, GOAL, width_px=2)
    _robot(paint, parameters, _pose(goal), GHOST, GHOST_EDGE, (GHOST, GHOST))

    wheel_colors: list[Color] = [WHEEL, WHEEL]
    stick_color = INK
    if sliding is not None:
        flags = np.asarray(sliding)
        if flags.shape != (3,):
            raise ValueError(
                f"sliding must have shape (3,) (left wheel, right wheel, stick), "
                f"got shape {flags.shape}"
            )
        wheel_colors = [SLIPPING if flags[i] else ROLLING for i in range(2)]
        stick_color = SLIPPING if flags[2] else ROLLING
    pose = _pose(state)
    _robot(paint, parameters, pose, LINK_2, INK, wheel_colors)
    contacts = _place(pose, _contact_points(parameters))
    paint.disc(contacts[2], 0.25 * parameters.wheel_radius, stick_color, INK)
    paint.disc((pose[0], pose[1]), 0.15 * parameters.wheel_radius, INK)

    if contact_forces is not None:
        forces = np.asarray(contact_forces, dtype=np.float64)
        if forces.shape != (3, 2):
            raise ValueError(
                f"contact_forces must have shape (3, 2) (F_x, F_y per contact), "
                f"got shape {forces.shape}"
            )
        if not np.all(np.isfinite(forces)):
            raise ValueError(f"contact_forces must be finite, got {forces}")
        limit = 0.5 * parameters.mass * parameters.gravity * max(
            parameters.wheel_friction, parameters.stick_friction
        )
        meters_per_newton = DIFF_DRIVE_FORCE_LENGTH / limit if limit > 0.0 else 0.0
        for contact, force in zip(contacts, forces, strict=True):
            fx, fy = _rotate((float(force[0]), float(force[1])), pose[2])
            magnitude = math.hypot(fx, fy)
            length = min(meters_per_newton * magnitude, DIFF_DRIVE_MAX_ARROW)
            if paint.view.scale * length < 2.0:
                continue
            head = (contact[0] + length * fx / magnitude, contact[1] + length * fy / magnitude)
            paint.arrow(contact, head, 0.4 * parameters.wheel_radius, FORCE)
    return paint.finish()


# --- bouncing ball --------------------------------------------------------------------------


def draw_bouncing_ball(
    q: ArrayLike,
    parameters: BouncingBallParameters,
    target_height: float | None = None,
    size: tuple[int, int] = (500, 500),
    view_height: float | None = None,
) -> pygame.Surface:
    """Side view of the ball over hatched ground, with its shadow and a target height.

    The camera follows the ball horizontally (the hatching shows the motion) and keeps a fixed
    height range: from a little below the ground to ``view_height``. A ball above the view is
    marked by a red triangle at the top edge.

    Args:
        q: (2,) position (x, y) [m] of the ball's centre; the ground is y = 0.
        parameters: the model's parameters; the radius [m] sets the ball.
        target_height: height [m] of the ball's centre to reach, drawn as a dashed green line;
            None draws none.
        size: canvas (width, height) [px].
        view_height: height [m] shown above the ground; default the larger of 1.2 m,
            1.25 target_height and 8 radii.

    Returns:
        The canvas, a ``pygame.Surface`` of ``size``.

    Raises:
        ValueError: if q is not a finite array of shape (2,) or view_height is not positive.
    """
    x, y = _state(q, ("x", "y"))
    size = _check_size(size)
    radius = parameters.radius
    if view_height is None:
        view_height = max(BALL_VIEW_HEIGHT, 8.0 * radius,
                          1.25 * target_height if target_height is not None else 0.0)
    if not view_height > 0.0:
        raise ValueError(f"view_height must be > 0 [m], got {view_height}")
    bottom = -0.12 * view_height
    aspect = size[0] / size[1]
    half_width = 0.5 * aspect * (view_height - bottom)
    paint = _Painter(_View((x - half_width, x + half_width), (bottom, view_height), size),
                     size, BACKGROUND)
    (x0, x1) = paint.view.x_range

    paint.polygon([(x0, bottom - 1.0), (x1, bottom - 1.0), (x1, 0.0), (x0, 0.0)], GROUND)
    spacing = view_height / 20.0
    for k in range(math.floor(x0 / spacing), math.ceil(x1 / spacing) + 2):
        paint.hairline((k * spacing, 0.0), (k * spacing - 0.6 * spacing, -0.6 * spacing),
                       BRAKE_RELEASED)
    paint.segment((x0, 0.0), (x1, 0.0), 0.006 * view_height, INK)

    if target_height is not None:
        paint.dashed((x0, target_height), (x1, target_height), 0.02 * view_height,
                     0.005 * view_height, GOAL)

    lift = float(np.clip((y - radius) / view_height, 0.0, 1.0))
    shade = tuple(int(round(g + (s - g) * (1.0 - lift))) for g, s in zip(GROUND, (150, 152, 148),
                                                                          strict=True))
    cx, cy = paint.view.px((x, 0.0))
    rx = paint.view.length(radius * (1.0 + 0.6 * lift))
    ry = max(1, paint.view.length(0.25 * radius))
    paint.gfxdraw.aaellipse(paint.surface, cx, cy, rx, ry, shade)
    paint.gfxdraw.filled_ellipse(paint.surface, cx, cy, rx, ry, shade)

    if y - radius > view_height:
        top = paint.view.y_range[1]
        mark = 0.03 * view_height
        paint.polygon([(x, top), (x - mark, top - 1.5 * mark), (x + mark, top - 1.5 * mark)],
                      BALL, INK)
    else:
        paint.disc((x, y), radius, BALL, INK)
        paint.disc((x - 0.35 * radius, y + 0.35 * radius), 0.3 * radius, BALL_HIGHLIGHT)
    return paint.finish()


# --- block on a slope -----------------------------------------------------------------------


def draw_sliding_block(
    q: ArrayLike,
    parameters: SlidingBlockParameters,
    target_position: float | None = None,
    size: tuple[int, int] = (500, 500),
    view_width: float | None = None,
) -> pygame.Surface:
    """Side view of the block on its slope, with distance ticks and a target flag.

    The slope descends to the right at ``slope_angle``; the camera follows the block along it
    (the ticks, every 1-2-5 x 10^k m with a tall one at s = 0, show the motion). The model is a
    point mass: the block is drawn as a square a tenth of the view wide.

    Args:
        q: (2,) coordinates (s, n) [m]: along the slope (positive down-slope) and the normal
            distance of the contact face from the slope.
        parameters: the model's parameters; slope_angle [rad] tilts the scene.
        target_position: s [m] to reach, drawn as a green flag; None draws none.
        size: canvas (width, height) [px].
        view_width: width [m] of world shown (default 4 m).

    Returns:
        The canvas, a ``pygame.Surface`` of ``size``.

    Raises:
        ValueError: if q is not a finite array of shape (2,) or view_width is not positive.
    """
    s, n = _state(q, ("s", "n"))
    size = _check_size(size)
    width = SLOPE_VIEW_WIDTH if view_width is None else view_width
    if not width > 0.0:
        raise ValueError(f"view_width must be > 0 [m], got {view_width}")
    theta = parameters.slope_angle
    down: Point = (math.cos(theta), -math.sin(theta))  # unit vector along +s
    normal: Point = (math.sin(theta), math.cos(theta))  # unit outward normal of the slope

    def at(along: float, off: float) -> Point:
        return (along * down[0] + off * normal[0], along * down[1] + off * normal[1])

    side = 0.1 * width
    center = at(s, 0.5 * side)
    height = width * size[1] / size[0]
    paint = _Painter(
        _View((center[0] - 0.5 * width, center[0] + 0.5 * width),
              (center[1] - 0.5 * height, center[1] + 0.5 * height), size),
        size, BACKGROUND,
    )
    reach = 2.0 * (width + height)  # [m] beyond every visible point
    upper, lower = at(s - reach, 0.0), at(s + reach, 0.0)
    depth = paint.view.y_range[0] - 1.0
    paint.polygon([upper, lower, (lower[0], depth), (upper[0], depth)], GROUND)
    paint.segment(upper, lower, 0.006 * width, INK)

    spacing = _nice_spacing(width)
    for k in range(math.floor((s - width) / spacing), math.ceil((s + width) / spacing) + 1):
        tick = 0.04 * width if k != 0 else 0.12 * width
        paint.segment(at(k * spacing, 0.0), at(k * spacing, -tick), 0.004 * width, INK)

    if target_position is not None:
        foot = at(target_position, 0.0)
        top = (foot[0], foot[1] + 1.6 * side)
        paint.segment(foot, top, 0.006 * width, INK)
        paint.polygon([top, (top[0] + 0.7 * side, top[1] - 0.25 * side),
                       (top[0], top[1] - 0.5 * side)], GOAL, INK)

    half = 0.5 * side
    paint.polygon([at(s - half, n), at(s + half, n), at(s + half, n + side),
                   at(s - half, n + side)], BLOCK, BLOCK_EDGE)
    return paint.finish()


# --- showing and saving ---------------------------------------------------------------------


class Viewer:
    """Owns the canvas; in "human" mode also a window, ticked at ``render_fps``.

    Environments create one in ``__init__`` from their ``render_mode``, pass each drawing to
    ``show`` in ``render()`` and call ``close`` in ``close()``. The window opens at the first
    ``show``; "rgb_array" mode needs no display at all.

    Args:
        render_mode: "human" or "rgb_array".
        size: window and array (width, height) [px].
        render_fps: frames per second a "human" window is held to.
        title: window caption.

    Raises:
        ValueError: for another render mode, a non-positive size or frame rate.
    """

    RENDER_MODES: ClassVar[tuple[str, ...]] = ("human", "rgb_array")

    def __init__(
        self,
        render_mode: str,
        size: tuple[int, int] = (500, 500),
        render_fps: int = RENDER_FPS,
        title: str = "mdi-envs",
    ) -> None:
        if render_mode not in self.RENDER_MODES:
            raise ValueError(
                f"render_mode must be one of {self.RENDER_MODES}, got {render_mode!r}"
            )
        if render_fps <= 0:
            raise ValueError(f"render_fps must be > 0, got {render_fps}")
        self.render_mode = render_mode
        self.size = _check_size(size)
        self.render_fps = render_fps
        self.title = title
        self._pygame = _import_pygame()
        self._window: pygame.Surface | None = None
        self._clock: pygame.time.Clock | None = None

    def show(self, canvas: pygame.Surface) -> NDArray[np.uint8] | None:
        """Show one drawing (scaled smoothly to ``size`` if it differs).

        Args:
            canvas: a drawing, e.g. from ``draw_manipulator``.

        Returns:
            In "rgb_array" mode a fresh (H, W, 3) uint8 array of the canvas; in "human" mode
            None, after blitting it to the window, pumping the event queue and ticking the clock.
        """
        pygame = self._pygame
        if canvas.get_size() != self.size:
            canvas = pygame.transform.smoothscale(canvas, self.size)
        if self.render_mode == "rgb_array":
            pixels = pygame.surfarray.array3d(canvas)  # (W, H, 3), a copy
            return np.ascontiguousarray(np.transpose(pixels, (1, 0, 2)), dtype=np.uint8)
        if self._window is None:
            pygame.display.init()
            pygame.display.set_caption(self.title)
            self._window = pygame.display.set_mode(self.size)
            self._clock = pygame.time.Clock()
        assert self._clock is not None
        self._window.blit(canvas, (0, 0))
        pygame.event.pump()
        self._clock.tick(self.render_fps)
        pygame.display.flip()
        return None

    def close(self) -> None:
        """Close the window, if one is open (safe to call more than once)."""
        if self._window is not None:
            self._pygame.display.quit()
            self._window = None
            self._clock = None


ANIMATION_SUFFIXES = (".gif", ".mp4")


def _frame_array(frame: ArrayLike, index: int) -> NDArray[np.uint8]:
    array = np.asarray(frame)
    if array.ndim != 3 or array.shape[2] != 3 or array.dtype != np.uint8:
        raise ValueError(
            f"frame {index} must be an (H, W, 3) uint8 array, "
            f"got shape {array.shape} and dtype {array.dtype}"
        )
    return array


def save_animation(
    frames: Sequence[NDArray[np.uint8]], path: str | os.PathLike[str], fps: int = 30
) -> pathlib.Path:
    """Write RGB frames as an animation; the suffix of ``path`` picks the format.

    ".gif" uses Pillow (each frame shown 1000 / fps ms, rounded by the format to 10 ms; the
    animation loops; identical consecutive frames merge into one longer frame). ".mp4" uses
    imageio with its ffmpeg plugin (``pip install imageio imageio-ffmpeg``); H.264 needs even
    width and height.

    Args:
        frames: (H, W, 3) uint8 arrays, all of one shape, e.g. from ``Viewer.show``.
        path: output file ending in ".gif" or ".mp4".
        fps: frames per second.

    Returns:
        The path written.

    Raises:
        ValueError: for another suffix, no frames, frames of the wrong or differing shapes, or
            a non-positive fps.
        ImportError: if the writer for the suffix is not installed.
    """
    out = pathlib.Path(path)
    suffix = out.suffix.lower()
    if suffix not in ANIMATION_SUFFIXES:
        raise ValueError(
            f"unsupported animation format {out.suffix!r} for {out}: use one of "
            f"{', '.join(ANIMATION_SUFFIXES)}"
        )
    if len(frames) == 0:
        raise ValueError("no frames to save")
    if fps <= 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    arrays = [_frame_array(frame, index) for index, frame in enumerate(frames)]
    for index, array in enumerate(arrays):
        if array.shape != arrays[0].shape:
            raise ValueError(
                f"frame {index} has shape {array.shape}, frame 0 has {arrays[0].shape}"
            )
    if suffix == ".gif":
        _save_gif(arrays, out, fps)
    else:
        _save_mp4(arrays, out, fps)
    return out


def _save_gif(frames: list[NDArray[np.uint8]], path: pathlib.Path, fps: int) -> None:
    try:
        from PIL import Image
    except ImportError as error:  # pragma: no cover - Pillow comes with matplotlib
        raise ImportError("GIF animations need Pillow: pip install pillow") from error
    images = [Image.fromarray(frame) for frame in frames]
    images[0].save(path, save_all=True, append_images=images[1:],
                   duration=max(1, round(1000 / fps)), loop=0)


def _save_mp4(frames: list[NDArray[np.uint8]], path: pathlib.Path, fps: int) -> None:
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401 - the plugin the "FFMPEG" format needs
    except ImportError as error:
        raise ImportError(
            "MP4 animations need imageio and imageio-ffmpeg: pip install imageio imageio-ffmpeg "
            "(or save a .gif, which needs only Pillow)"
        ) from error
    images: list[Any] = list(frames)
    imageio.mimwrite(path, images, format="FFMPEG", fps=fps, macro_block_size=1)


__all__ = [
    "ANIMATION_SUFFIXES",
    "Viewer",
    "draw_bouncing_ball",
    "draw_diff_drive",
    "draw_manipulator",
    "draw_sliding_block",
    "save_animation",
]
