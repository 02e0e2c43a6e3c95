"""Tests of the pygame drawings, the viewer and the animation writer (``mdi_envs/rendering.py``)."""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ["SDL_VIDEODRIVER"] = "dummy"  # headless: before pygame is first imported

import numpy as np
import pytest

pygame = pytest.importorskip("pygame")

from mdi_envs.mechanics.models import (  # noqa: E402
    BlockableManipulatorParameters,
    BouncingBallParameters,
    DiffDriveParameters,
    SlidingBlockParameters,
)
from mdi_envs.rendering import (  # noqa: E402
    Viewer,
    draw_bouncing_ball,
    draw_diff_drive,
    draw_manipulator,
    draw_sliding_block,
    save_animation,
)

SIZE = (160, 120)  # (width, height) [px]: small and not square, to catch transposes
GOAL_POSE = (2.0, 5.0, -math.pi / 2)


def pixels(surface: Any) -> np.ndarray:
    """(H, W, 3) array of a surface."""
    return np.transpose(pygame.surfarray.array3d(surface), (1, 0, 2))


def differs(first: Any, second: Any) -> bool:
    return bool(np.any(pixels(first) != pixels(second)))


SCENES: dict[str, Callable[..., Any]] = {
    "manipulator": lambda q=(0.3, 1.2), size=SIZE: draw_manipulator(
        q, True, 0.5, BlockableManipulatorParameters(), size=size),
    "diff_drive": lambda q=(0.5, 1.0, 0.4, 0.0, 0.0), size=SIZE: draw_diff_drive(
        q, DiffDriveParameters(), GOAL_POSE, contact_forces=np.ones((3, 2)),
        sliding=(False, True, True), trail=[(0.0, 0.0), (0.2, 0.5), (0.5, 1.0)], size=size),
    "bouncing_ball": lambda q=(0.0, 0.4), size=SIZE: draw_bouncing_ball(
        q, BouncingBallParameters(), target_height=0.8, size=size),
    "sliding_block": lambda q=(0.3, 0.0), size=SIZE: draw_sliding_block(
        q, SlidingBlockParameters(), target_position=1.0, size=size),
}
WRONG_Q = {
    "manipulator": (0.0, 0.0, 0.0),
    "diff_drive": (0.0, 0.0, 0.0),
    "bouncing_ball": [[0.0, 0.0]],
    "sliding_block": (0.0,),
}


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_drawing_has_the_size_and_is_not_blank(scene: str) -> None:
    array = pixels(SCENES[scene]())
    assert array.shape == (SIZE[1], SIZE[0], 3)
    assert len(np.unique(array.reshape(-1, 3), axis=0)) > 2


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_wrong_q_shape_names_the_expected_shape(scene: str) -> None:
    with pytest.raises(ValueError, match=r"shape \((2|5),\)"):
        SCENES[scene](q=WRONG_Q[scene])


def test_non_finite_q_is_rejected() -> None:
    with pytest.raises(ValueError, match="finite"):
        SCENES["manipulator"](q=(math.nan, 0.0))


def test_manipulator_shows_the_brake_and_the_pose() -> None:
    parameters = BlockableManipulatorParameters()
    engaged = draw_manipulator((0.3, 1.2), True, 0.5, parameters, size=SIZE)
    released = draw_manipulator((0.3, 1.2), False, 0.5, parameters, size=SIZE)
    moved = draw_manipulator((0.9, 0.2), True, 0.5, parameters, size=SIZE)
    reversed_torque = draw_manipulator((0.3, 1.2), True, -0.5, parameters, size=SIZE)
    assert differs(engaged, released)
    assert differs(engaged, moved)
    assert differs(engaged, reversed_torque)


def test_diff_drive_shows_a_sliding_wheel() -> None:
    parameters = DiffDriveParameters()
    q = (0.5, 1.0, 0.4, 0.0, 0.0)
    rolling = draw_diff_drive(q, parameters, GOAL_POSE, sliding=(False, False, True), size=SIZE)
    slipping = draw_diff_drive(q, parameters, GOAL_POSE, sliding=(True, False, True), size=SIZE)
    assert differs(rolling, slipping)


def test_diff_drive_rejects_badly_shaped_extras() -> None:
    parameters = DiffDriveParameters()
    q = np.zeros(5)
    with pytest.raises(ValueError, match=r"\(3, 2\)"):
        draw_diff_drive(q, parameters, GOAL_POSE, contact_forces=np.zeros(6))
    with pytest.raises(ValueError, match=r"\(3,\)"):
        draw_diff_drive(q, parameters, GOAL_POSE, sliding=(True, False))
    with pytest.raises(ValueError, match=r"\(k, 2\)"):
        draw_diff_drive(q, parameters, GOAL_POSE, trail=np.zeros((4, 3)))


def test_y_axis_points_up() -> None:
    # The ball's red pixels sit higher on screen (smaller row) when the ball is higher.
    def red_row(height: float) -> float:
        array = pixels(draw_bouncing_ball((0.0, height), BouncingBallParameters(), size=SIZE))
        red = (array[:, :, 0] > 180) & (array[:, :, 1] < 110) & (array[:, :, 2] < 110)
        return float(np.argwhere(red)[:, 0].mean())

    assert red_row(0.9) < red_row(0.2)


def test_rgb_array_viewer_returns_a_uint8_copy() -> None:
    viewer = Viewer("rgb_array", size=SIZE)
    canvas = SCENES["manipulator"]()
    frame = viewer.show(canvas)
    assert isinstance(frame, np.ndarray)
    assert frame.shape == (SIZE[1], SIZE[0], 3) and frame.dtype == np.uint8
    np.testing.assert_array_equal(frame, pixels(canvas))
    scaled = viewer.show(SCENES["manipulator"](size=(80, 60)))
    assert scaled is not None and scaled.shape == (SIZE[1], SIZE[0], 3)
    viewer.close()


def test_human_viewer_runs_headless() -> None:
    viewer = Viewer("human", size=SIZE, render_fps=1000)
    assert viewer.show(SCENES["bouncing_ball"]()) is None
    assert viewer.show(SCENES["bouncing_ball"](q=(0.0, 0.3))) is None
    viewer.close()
    viewer.close()


def test_viewer_rejects_an_unknown_mode() -> None:
    with pytest.raises(ValueError, match="rgb_array"):
        Viewer("ansi")


def frames(num: int) -> list[np.ndarray]:
    # Consecutive GIF frames must differ, or Pillow merges them.
    viewer = Viewer("rgb_array", size=SIZE)
    out = []
    for k in range(num):
        frame = viewer.show(SCENES["sliding_block"](q=(0.2 * k, 0.0)))
        assert frame is not None
        out.append(frame)
    return out


def test_gif_reads_back_with_every_frame(tmp_path: Path) -> None:
    from PIL import Image

    path = save_animation(frames(4), tmp_path / "block.gif", fps=20)
    assert path == tmp_path / "block.gif"
    with Image.open(path) as image:
        assert image.n_frames == 4
        assert image.size == SIZE
        assert image.info["duration"] == 50
        assert image.info["loop"] == 0


def test_animation_rejects_bad_input(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"\.gif, \.mp4"):
        save_animation(frames(1), tmp_path / "block.avi")
    with pytest.raises(ValueError, match="no frames"):
        save_animation([], tmp_path / "block.gif")
    with pytest.raises(ValueError, match=r"\(H, W, 3\) uint8"):
        save_animation([np.zeros((4, 4), dtype=np.uint8)], tmp_path / "block.gif")


def test_mp4_without_imageio_says_what_to_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "imageio", None)  # as if not installed
    with pytest.raises(ImportError, match="imageio-ffmpeg"):
        save_animation(frames(2), tmp_path / "block.mp4")
