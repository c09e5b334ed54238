"""`ms2 teleop` driven by real X key events (xdotool on a virtual X server): the session lifts
LiftCube-v0's cube, saves the episode, and `ms2 replay` replays the file with the recorded
success."""

from __future__ import annotations

import json
import subprocess
import sys

import gymnasium as gym
import h5py
import ms2  # noqa: F401
import numpy as np
import pytest
from ms2.teleop import TRANSLATE_KEYS, Teleop, keys_help
from xserver import XServer

ENV_ID = "LiftCube-v0"
SEED = 3  # the session's first episode (discarded with r)
PLAN_SEED = SEED + 1  # the episode the key plan drives
STEP = 0.3  # normalized translation per key press (3 cm requested)


def quat_wxyz_to_matrix(q):
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _key_towards(delta_world, tcp_q):
    """The translation key whose TCP-frame axis best reduces ``delta_world``."""
    delta_tcp = quat_wxyz_to_matrix(tcp_q).T @ delta_world
    axis = int(np.argmax(np.abs(delta_tcp)))
    sign = 1.0 if delta_tcp[axis] > 0 else -1.0
    return next(k for k, (i, s) in TRANSLATE_KEYS.items() if i == axis and s == sign)


def plan_lift_keys(max_keys=200):
    """Key presses that lift the cube, found by simulating them on a copy of the env (same
    seed and action mapping as the teleop session: the simulation is deterministic, so the
    session replays them exactly). Greedy: align over the cube, descend, close, lift, hold."""
    env = gym.make(ENV_ID, obs_mode="state_dict", control_mode="pd_ee_delta_pose")
    obs, _ = env.reset(seed=PLAN_SEED)
    keys, gripper, phase, hold = [], 1.0, "align", 0
    info = {"success": False}
    while len(keys) < max_keys and not info["success"]:
        tcp, cube = obs["extra"]["tcp_pose"], obs["extra"]["obj_pose"][:3]
        if phase == "align":
            delta = cube - tcp[:3]
            delta[2] = 0.0
            key = _key_towards(delta, tcp[3:]) if np.linalg.norm(delta) > 0.006 else None
            if key is None:
                phase = "descend"
                continue
        elif phase == "descend":
            delta = np.array([0.0, 0.0, cube[2] - tcp[2]])
            key = _key_towards(delta, tcp[3:]) if abs(delta[2]) > 0.008 else "g"
            if key == "g":
                phase, hold = "close", 0
        elif phase == "close":
            key, hold = "g", hold + 1
            if hold >= 6:
                phase = "lift"
        else:  # lift, then hold still (the robot must be static for success)
            high = cube[2] > 0.26
            key = "g" if high else _key_towards(np.array([0.0, 0.0, 1.0]), tcp[3:])
        keys.append(key)
        gripper = -1.0 if key == "g" else (1.0 if key == "f" else gripper)
        action = np.zeros(env.action_space.shape, dtype=np.float32)
        if key in TRANSLATE_KEYS:
            index, sign = TRANSLATE_KEYS[key]
            action[index] = sign * STEP
        action[-1] = gripper
        obs, _, _, _, info = env.step(action)
    env.close()
    return keys, bool(info["success"])


@pytest.fixture(scope="module")
def xserver():
    server = XServer()
    yield server
    server.close()


def test_keys_are_documented():
    text = keys_help()
    for key in ("i / k", "u / o", "f / g", "v", "r", "q / escape", "mouse"):
        assert key in text
    out = subprocess.run(
        [sys.executable, "-m", "ms2", "teleop", "--help"], capture_output=True, text=True
    )
    assert (
        out.returncode == 0 and "save the episode" in out.stdout and "(default: 0.1)" in out.stdout
    )


def test_bad_arguments_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="translation_step"):
        Teleop(ENV_ID, tmp_path / "t.h5", translation_step=2.0)
    with pytest.raises(ValueError, match=r"\.h5"):
        Teleop(ENV_ID, tmp_path / "t.txt")


def test_auto_repeats_move_but_never_save_reset_or_quit_twice(tmp_path):
    teleop = Teleop(ENV_ID, tmp_path / "t.h5")
    teleop._new_episode()
    seed = teleop.seed
    assert teleop.handle_key("i") and teleop.handle_key("i", repeat=True)
    assert teleop.steps == 2, "a held move key moves on every repeat"
    assert teleop.handle_key("r", repeat=True) and teleop.seed == seed, "a repeat is no reset"
    assert teleop.handle_key("q", repeat=True), "a repeat of q does not quit"
    assert teleop.handle_key("v", repeat=True) and not teleop.saved_success
    assert teleop.handle_key("r") and teleop.seed == seed + 1
    assert not teleop.handle_key("q")
    teleop.env.close()


def test_scripted_key_session_saves_a_replayable_successful_episode(xserver, tmp_path):
    keys, planned_success = plan_lift_keys()
    assert planned_success, "the key plan itself must lift the cube"
    out_h5 = tmp_path / "teleop.h5"
    proc = subprocess.Popen(
        [
            sys.executable, "-m", "ms2", "teleop", ENV_ID,
            "--output", str(out_h5),
            "--seed", str(SEED),
            "--translation-step", str(STEP),
        ],
        env=xserver.env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        window = xserver.find_window(f"ms2 {ENV_ID}", timeout_s=120)
        # A first episode that is discarded (r), then the planned one, saved (v), then quit.
        xserver.keys(window, ["i", "i", "r"])
        xserver.keys(window, keys + ["v", "q"])
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, stderr
    assert "saved episode 0" in stdout and "success=True" in stdout, stdout
    meta = json.loads(out_h5.with_suffix(".json").read_text())
    assert meta["env_info"]["env_id"] == ENV_ID
    assert meta["env_info"]["env_kwargs"]["control_mode"] == "pd_ee_delta_pose"
    (episode,) = meta["episodes"]
    assert episode["episode_seed"] == PLAN_SEED, "r started a new episode with the next seed"
    assert episode["elapsed_steps"] == len(keys)
    with h5py.File(out_h5, "r") as f:
        actions = f["traj_0/actions"][()]
        success = f["traj_0/success"][()]
        assert f["traj_0/env_states"].shape[0] == len(keys) + 1
    assert actions.shape == (len(keys), 7) and bool(success[-1])
    moved = actions[:, :3][np.any(actions[:, :3] != 0, axis=1)]
    assert np.allclose(np.abs(moved).sum(axis=1), STEP), "one axis per key press"

    replay = subprocess.run(
        [sys.executable, "-m", "ms2", "replay", "--traj-path", str(out_h5), "-q"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert replay.returncode == 0, replay.stderr
    assert "replayed 1 episodes: 1 succeeded" in replay.stdout, replay.stdout
