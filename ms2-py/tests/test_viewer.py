"""The viewer window (``render_mode="human"``) on a virtual X server: what it shows (the robot
where it projects, sensor and segmentation views), mouse orbit / pan / zoom and the pause and
single-step keys as real X input events, and the error without a display."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import gymnasium as gym
import ms2  # noqa: F401
import numpy as np
import pytest
from xserver import XServer

ENV_ID = "PickCube-v0"


@pytest.fixture(scope="module")
def xserver():
    server = XServer()
    old = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = server.display
    yield server
    if old is None:
        os.environ.pop("DISPLAY", None)
    else:
        os.environ["DISPLAY"] = old
    server.close()


@pytest.fixture(scope="module")
def viewed(xserver):
    """A PickCube env with render_mode='human', its viewer window open and drawn once."""
    env = gym.make(ENV_ID, obs_mode="state_dict", render_mode="human")
    obs, _ = env.reset(seed=0)
    assert env.render() is None  # gymnasium's rule for human rendering
    viewer = env.unwrapped.viewer
    assert viewer is env.unwrapped.render_human()
    window = xserver.find_window(f"ms2 {ENV_ID}")
    yield env, obs, viewer, window
    env.close()


def quat_wxyz_to_matrix(q):
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def project(point, eye, target, fov_y, width, height):
    """Pixel (column, row) of a world point seen by a z-up look-at pinhole camera."""
    eye, target, point = (np.asarray(v, dtype=np.float64) for v in (eye, target, point))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = point - eye
    focal = (height / 2) / np.tan(fov_y / 2)
    depth = d @ forward
    return (
        (width - 1) / 2 + focal * (d @ right) / depth,
        (height - 1) / 2 - focal * (d @ up) / depth,
    )


def robot_grey_share(patch):
    """Share of pixels with the robot's paint: grey/white (channels within 8 of each other,
    brighter than 60). The floor is slate blue (B > R by ~25)."""
    patch = patch.reshape(-1, 3).astype(int)
    spread = patch.max(axis=1) - patch.min(axis=1)
    return float(np.mean((spread <= 8) & (patch.mean(axis=1) > 60)))


def window_image(xserver, window):
    time.sleep(0.2)  # the X server draws the last frame asynchronously
    x, y, w, h = xserver.geometry(window)
    shot = xserver.screenshot()
    return shot[y : y + h, x : x + w]


def test_window_shows_the_robot_where_it_projects(xserver, viewed):
    env, obs, viewer, window = viewed
    viewer.show(env.unwrapped._native)
    image = window_image(xserver, window)
    width, height = viewer.size()
    assert image.shape == (height, width, 3)
    eye, target = viewer.camera()
    tcp = obs["extra"]["tcp_pose"]
    hand = tcp[:3] + quat_wxyz_to_matrix(tcp[3:]) @ np.array([0.0, 0.0, -0.08])
    base_column = np.array([-0.615, 0.0, 0.2])
    floor = np.array([0.25, -0.35, 0.0])
    shares = {}
    for name, point in (("hand", hand), ("base", base_column), ("floor", floor)):
        col, row = project(point, eye, target, 1.0, width, height)
        c, r = int(round(col)), int(round(row))
        assert 3 <= c < width - 3 and 3 <= r < height - 3, (name, c, r)
        shares[name] = robot_grey_share(image[r - 3 : r + 4, c - 3 : c + 4])
    assert shares["hand"] > 0.5 and shares["base"] > 0.5, shares
    assert shares["floor"] < 0.1, shares
    # The window is not just the robot: most of it is the floor, blue-grey.
    flat = image.reshape(-1, 3).astype(int)
    assert np.mean((flat[:, 2] - flat[:, 0]) > 10) > 0.3


def test_window_follows_the_simulation(xserver, viewed):
    env, _, viewer, window = viewed
    env.reset(seed=0)
    viewer.show(env.unwrapped._native)
    before = window_image(xserver, window)
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    action[1] = 1.0  # joint 2 forward: the arm swings down
    for _ in range(8):
        env.step(action)
        env.render()
    after = window_image(xserver, window)
    changed = np.mean(np.any(before != after, axis=2))
    assert changed > 0.01, changed
    env.reset(seed=0)


def test_mouse_orbits_pans_and_zooms(xserver, viewed):
    env, _, viewer, window = viewed
    native = env.unwrapped._native
    x, y, w, h = xserver.geometry(window)
    eye0, target0 = (np.array(v) for v in viewer.camera())
    xserver.xdotool("mousemove", str(x + w // 2), str(y + h // 2))
    xserver.xdotool("mousedown", "1")
    xserver.xdotool("mousemove", str(x + w // 2 + 120), str(y + h // 2 + 30))
    xserver.xdotool("mouseup", "1")
    time.sleep(0.2)
    viewer.show(native)
    eye1, target1 = (np.array(v) for v in viewer.camera())
    np.testing.assert_allclose(target1, target0, atol=1e-6)
    assert np.linalg.norm(eye1 - eye0) > 0.1, "a left drag orbits the eye"
    np.testing.assert_allclose(
        np.linalg.norm(eye1 - target1), np.linalg.norm(eye0 - target0), rtol=1e-4
    )
    xserver.xdotool("click", "4")  # wheel up: zoom in
    time.sleep(0.2)
    viewer.show(native)
    eye2, target2 = (np.array(v) for v in viewer.camera())
    assert np.linalg.norm(eye2 - target2) < np.linalg.norm(eye1 - target1) * 0.95
    xserver.xdotool("mousedown", "3")
    xserver.xdotool("mousemove", str(x + w // 2 - 100), str(y + h // 2))
    xserver.xdotool("mouseup", "3")
    time.sleep(0.2)
    viewer.show(native)
    _, target3 = (np.array(v) for v in viewer.camera())
    assert np.linalg.norm(target3 - target2) > 0.02, "a right drag pans the target"


def test_pause_blocks_render_until_single_step(xserver, viewed):
    env, _, viewer, window = viewed
    native = env.unwrapped._native
    xserver.keys(window, ["space"])
    time.sleep(0.2)
    viewer.poll()
    assert viewer.paused
    assert "PAUSED" in viewer.describe(native)
    timer = threading.Timer(0.8, lambda: xserver.keys(window, ["n"]))
    timer.start()
    started = time.monotonic()
    env.render()  # blocks, keeping the window live, until `n`
    waited = time.monotonic() - started
    timer.join()
    assert waited >= 0.7, waited
    assert viewer.paused, "a single step keeps the viewer paused"
    xserver.keys(window, ["space"])
    time.sleep(0.2)
    started = time.monotonic()
    env.render()
    assert not viewer.paused and time.monotonic() - started < 5.0
    assert viewer.take_keys() == [], "the viewer's own keys are not passed on"


def test_sensor_and_segmentation_views(xserver, viewed):
    env, _, viewer, window = viewed
    native = env.unwrapped._native
    xserver.keys(window, ["c"])
    time.sleep(0.2)
    env.render()
    assert "base_camera (colour)" in viewer.describe(native)
    colour = window_image(xserver, window)
    xserver.keys(window, ["m"])
    time.sleep(0.2)
    env.render()
    assert "base_camera (segmentation)" in viewer.describe(native)
    seg = window_image(xserver, window)
    n_colour = len(np.unique(colour.reshape(-1, 3), axis=0))
    n_seg = len(np.unique(seg.reshape(-1, 3), axis=0))
    # Segmentation: one flat colour per object (ground, cube, robot links, background);
    # colour: shading gives hundreds.
    assert 4 <= n_seg <= 30 < 200 <= n_colour, (n_seg, n_colour)
    xserver.keys(window, ["c", "c"])  # hand_camera, then back to the free camera
    time.sleep(0.2)
    env.render()
    assert "free camera" in viewer.describe(native)


def test_other_keys_reach_the_application(xserver, viewed):
    env, _, viewer, window = viewed
    viewer.take_keys()
    xserver.keys(window, ["i", "5", "Escape"])
    time.sleep(0.2)
    viewer.poll()
    assert viewer.take_keys() == ["i", "5", "escape"]
    viewer.press_key("J")
    assert viewer.take_keys() == ["j"]
    viewer.press_key("i")
    viewer.press_key("i", repeat=True)
    viewer.press_key("space", repeat=True)  # the viewer's own keys ignore auto-repeats
    assert viewer.take_key_presses() == [("i", False), ("i", True)]
    assert not viewer.paused
    with pytest.raises(ValueError, match="key"):
        viewer.press_key("")


def _render_in_subprocess(env_vars):
    code = (
        "import gymnasium as gym, ms2\n"
        f"env = gym.make({ENV_ID!r}, render_mode='human')\n"
        "env.reset(seed=0)\n"
        "try:\n"
        "    env.render()\n"
        "except RuntimeError as e:\n"
        "    print('RuntimeError:', e)\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code], env=env_vars, capture_output=True, text=True, timeout=120
    )


def test_no_display_is_a_clear_runtime_error():
    env_vars = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    out = _render_in_subprocess(env_vars)
    assert out.returncode == 0, out.stderr
    assert "RuntimeError:" in out.stdout, out.stdout + out.stderr
    assert "DISPLAY is not set" in out.stdout and "WAYLAND_DISPLAY" in out.stdout
    assert "panic" not in (out.stdout + out.stderr).lower()


def test_unreachable_display_is_a_clear_runtime_error():
    out = _render_in_subprocess({**os.environ, "DISPLAY": ":4242"})
    assert out.returncode == 0, out.stderr
    assert "RuntimeError:" in out.stdout and 'DISPLAY=":4242"' in out.stdout, out.stdout
