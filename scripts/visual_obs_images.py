"""Renders ms2's base-camera, hand-camera and render() images of the PickCube-v0 states that
ManiSkill2 0.5.3's fixture images show (../shared/fixtures/maniskill2/images/, or the directory
given as the first argument), and writes one side-by-side PNG per state and view (ms2 left,
ManiSkill2 right) into docs/images/ (or the second argument), plus a table of depth figures.

Run from the repository root with the venv active: ``python scripts/visual_obs_images.py``.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import gymnasium as gym
import ms2  # noqa: F401  (registers the ids)
import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_FIXTURES = ROOT.parent / "shared/fixtures/maniskill2/images"
FIXTURES = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_FIXTURES
OUT = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT / "docs/images"


def ms2_state(env, fixture: dict) -> np.ndarray:
    """ms2's flat state for the fixture's robot qpos, cube pose and goal (velocities 0)."""
    state = env.unwrapped.get_state().copy()
    state[0:7] = fixture["cube_pose"]  # cube: p (3) + q (wxyz)
    state[7:13] = 0.0
    robot = 13 + 7  # after the cube and the robot's root pose
    for k, q in enumerate(fixture["robot_qpos"]):
        state[robot + 4 * k : robot + 4 * k + 4] = [q, 0.0, q, 0.0]
    state[-3:] = fixture["goal_pos"]
    return state


def save_pair(ours: np.ndarray, theirs: np.ndarray, path: Path) -> None:
    h = max(ours.shape[0], theirs.shape[0])
    gap = np.full((h, 4, 3), 255, np.uint8)
    tmp = path.with_suffix(".tmp.png")
    Image.fromarray(np.concatenate([ours, gap, theirs], axis=1)).save(tmp)
    os.replace(tmp, path)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    # pd_joint_pos: one step whose targets are the state's joint positions holds it (the
    # observation comes from that step).
    env = gym.make(
        "PickCube-v0",
        obs_mode="rgbd",
        render_mode="rgb_array",
        control_mode="pd_joint_pos",
    )
    rows = []
    for seed in (0, 1):
        fixture = json.loads(
            (FIXTURES / f"PickCube-v0_seed{seed}_state.json").read_text()
        )
        env.reset(seed=seed)
        env.unwrapped.set_state(ms2_state(env, fixture))
        hold = np.append(np.asarray(fixture["robot_qpos"][:7], np.float32), 1.0)
        obs = env.step(hold)[0]
        for cam in ("base_camera", "hand_camera"):
            ours = obs["image"][cam]["rgb"]
            theirs = np.asarray(
                Image.open(FIXTURES / f"PickCube-v0_seed{seed}_{cam}_rgb.png")
            )[..., :3]
            save_pair(ours, theirs, OUT / f"visual_obs_seed{seed}_{cam}.png")
            d_ours = obs["image"][cam]["depth"][..., 0]
            d_theirs = np.load(FIXTURES / f"PickCube-v0_seed{seed}_{cam}_depth.npy")
            if d_theirs.ndim == 3:
                d_theirs = d_theirs[..., 0]
            both = (d_ours > 0) & (d_theirs > 0)
            rows.append(
                (
                    seed,
                    cam,
                    100.0 * float((d_ours == 0).mean()),
                    100.0 * float((d_theirs == 0).mean()),
                    float(np.median(np.abs(d_ours[both] - d_theirs[both]))),
                )
            )
        theirs = np.asarray(
            Image.open(FIXTURES / f"PickCube-v0_seed{seed}_render.png")
        )[..., :3]
        save_pair(env.render(), theirs, OUT / f"visual_obs_seed{seed}_render.png")
    print("seed camera       zero-depth % ms2  ManiSkill2  median |depth diff| m")
    for seed, cam, z_ours, z_theirs, diff in rows:
        print(f"{seed:<4} {cam:<12} {z_ours:>15.1f} {z_theirs:>11.1f} {diff:>21.4f}")


if __name__ == "__main__":
    main()
