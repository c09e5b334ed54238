"""The object-variation pick tasks (PickSingleYCB-v0, PickSingleEGAD-v0, PickClutterYCB-v0) through
gymnasium, on a
small model set in ManiSkill2's layout written by the test (``MS2_YCB_DIR`` / ``MS2_EGAD_DIR``
point the tasks at it)."""

from __future__ import annotations

import json
import math

import gymnasium as gym
import ms2  # noqa: F401  (registers the envs)
import numpy as np
import pytest
from conftest import assert_obs_equal

#: (id, sides, circumradius m, height m, rgb) of the fixture's prisms.
MODELS = [
    ("box_a", 4, 0.035, 0.05, (0.8, 0.2, 0.2)),
    ("can_b", 10, 0.03, 0.09, (0.2, 0.6, 0.8)),
    ("bar_c", 4, 0.028, 0.1, (0.3, 0.8, 0.3)),
]


def prism_obj(sides, radius, height, mtl=None):
    lines = [f"mtllib {mtl}", "usemtl body"] if mtl else []
    lines.append("o piece0")
    for z in (0.0, height):
        for k in range(sides):
            a = 2 * math.pi * (k + 0.5) / sides
            lines.append(f"v {radius * math.cos(a)} {radius * math.sin(a)} {z}")
    n = sides
    for k in range(n):
        a, b = 1 + k, 1 + (k + 1) % n
        lines += [f"f {a} {b} {b + n}", f"f {a} {b + n} {a + n}"]
    for k in range(1, n - 1):
        lines += [f"f 1 {k + 2} {k + 1}", f"f {1 + n} {1 + n + k} {2 + n + k}"]
    return "\n".join(lines) + "\n"


def write_models(root, egad):
    info = {}
    for mid, sides, r, h, rgb in MODELS:
        info[mid] = {"bbox": {"min": [-r, -r, 0.0], "max": [r, r, h]}, "scales": [1.0]}
        if egad:
            col = root / "egad_train_set_coacd" / f"{mid}.obj"
            vis = root / "egad_train_set" / f"{mid}.obj"
        else:
            col = root / "models" / mid / "collision.obj"
            vis = root / "models" / mid / "textured.obj"
        col.parent.mkdir(parents=True, exist_ok=True)
        vis.parent.mkdir(parents=True, exist_ok=True)
        col.write_text(prism_obj(sides, r, h))
        mtl = vis.with_suffix(".mtl")
        mtl.write_text(f"newmtl body\nKd {rgb[0]} {rgb[1]} {rgb[2]}\n")
        vis.write_text(prism_obj(sides, r, h, mtl.name))
    name = "info_pick_train_v0.json" if egad else "info_pick_v0.json"
    (root / name).write_text(json.dumps(info))


@pytest.fixture(autouse=True)
def models(tmp_path_factory, monkeypatch):
    base = tmp_path_factory.getbasetemp() / "object_models"
    if not base.exists():
        write_models(base / "ycb", egad=False)
        write_models(base / "egad", egad=True)
    monkeypatch.setenv("MS2_YCB_DIR", str(base / "ycb"))
    monkeypatch.setenv("MS2_EGAD_DIR", str(base / "egad"))
    return base


@pytest.mark.parametrize("env_id", ["PickSingleYCB-v0", "PickSingleEGAD-v0"])
def test_state_layout_rewards_and_limit_match_maniskill2(env_id):
    env = gym.make(env_id, obs_mode="state", reward_mode="normalized_dense")
    obs, info = env.reset(seed=0)
    assert obs.shape == (51,) and obs.dtype == np.float32
    assert env.spec.max_episode_steps == 200
    assert set(info) >= {"success", "is_obj_placed", "is_robot_static"}
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert 0.0 <= reward <= 1.0
    dense = gym.make(env_id, obs_mode="state_dict", reward_mode="dense")
    obs, _ = dense.reset(seed=0)
    assert list(obs["extra"]) == [
        "tcp_pose",
        "goal_pos",
        "tcp_to_goal_pos",
        "obj_pose",
        "tcp_to_obj_pos",
        "obj_to_goal_pos",
    ]
    _, reward, *_ = dense.step(np.zeros(dense.action_space.shape, np.float32))
    assert 0.0 <= reward <= 10.0


def test_model_ids_keyword_and_per_episode_choice():
    env = gym.make("PickSingleYCB-v0", obs_mode="state_dict", model_ids=["can_b"])
    obs, _ = env.reset(seed=1)
    # The 9 cm can stands: its centre of mass 4.5 cm above the ground.
    assert abs(obs["extra"]["obj_pose"][2] - 0.045) < 0.006
    with pytest.raises(ValueError, match="nope"):
        gym.make("PickSingleYCB-v0", model_ids=["nope"])
    with pytest.raises(TypeError, match="model_ids"):
        gym.make("PickSingleYCB-v0", model_ids=3)
    with pytest.raises(ValueError, match="model_ids"):
        gym.make("PickCube-v0", model_ids=["can_b"])
    # Episodes draw their model from the seed: heights differ across seeds, equal for one seed.
    env = gym.make("PickSingleYCB-v0", obs_mode="state_dict")
    heights = set()
    for seed in range(10):
        obs, _ = env.reset(seed=seed)
        heights.add(round(float(obs["extra"]["obj_pose"][2]), 2))
    assert len(heights) >= 2
    a, _ = env.reset(seed=4)
    env.reset(seed=5)
    b, _ = env.reset(seed=4, options={"reconfigure": True})
    assert_obs_equal(a, b)


def test_model_id_and_scale_name_the_episode_s_model():
    # ManiSkill2's env.unwrapped.model_id / model_scale: the model drawn for the episode.
    env = gym.make("PickSingleYCB-v0", obs_mode="state_dict")
    seen = {}
    for seed in range(10):
        obs, _ = env.reset(seed=seed)
        model_id = env.unwrapped.model_id
        assert model_id in {mid for mid, *_ in MODELS}
        assert env.unwrapped.model_scale == 1.0
        height = next(h for mid, _, _, h, _ in MODELS if mid == model_id)
        # The drawn model is the one in the scene: its centre of mass sits at half its height.
        assert abs(obs["extra"]["obj_pose"][2] - height / 2) < 0.006, (seed, model_id)
        seen[seed] = model_id
    assert len(set(seen.values())) >= 2
    env.reset(seed=3)
    assert env.unwrapped.model_id == seen[3]
    only = gym.make("PickSingleEGAD-v0", model_ids=["bar_c"])
    only.reset(seed=0)
    assert only.unwrapped.model_id == "bar_c"
    cube = gym.make("PickCube-v0")
    cube.reset(seed=0)
    assert not hasattr(cube.unwrapped, "model_id")
    with pytest.raises(AttributeError, match="PickCube-v0"):
        _ = cube.unwrapped.model_scale


def test_state_round_trip():
    env = gym.make("PickSingleEGAD-v0", obs_mode="state").unwrapped
    env.reset(seed=2)
    env.step(env.action_space.sample())
    state = env.get_state()
    obs = env.get_obs() if hasattr(env, "get_obs") else None
    env.step(env.action_space.sample())
    env.set_state(state)
    np.testing.assert_array_equal(env.get_state(), state)
    if obs is not None:
        np.testing.assert_array_equal(env.get_obs(), obs)


def test_visual_modes_show_the_object():
    env = gym.make("PickSingleYCB-v0", obs_mode="rgbd", model_ids=["box_a"])
    obs, _ = env.reset(seed=0)
    rgb = obs["image"]["base_camera"]["rgb"]
    assert rgb.shape == (128, 128, 3)
    # The red box is in the base camera's view.
    red = (rgb[..., 0] > 120) & (rgb[..., 1] < 80) & (rgb[..., 2] < 80)
    assert red.sum() > 4
    assert set(obs["extra"]) == {"tcp_pose", "goal_pos"}


def test_make_vec_draws_different_objects_per_env():
    venv = ms2.make_vec("PickSingleYCB-v0", num_envs=3, obs_mode="state_dict")
    obs, _ = venv.reset(seed=[0, 1, 2])
    heights = obs["extra"]["obj_pose"][:, 2]
    assert heights.shape == (3,)
    venv.close()


def test_scripted_policy_picks_objects():
    env = gym.make("PickSingleYCB-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    policy = ms2.ScriptedPolicy(env)
    successes = 0
    for seed in range(5):
        env.reset(seed=seed)
        policy.reset()
        while True:
            _, _, terminated, truncated, info = env.step(policy.act())
            if terminated or truncated:
                break
        successes += bool(info["success"])
    assert successes >= 3, successes


def test_clutter_layout_rewards_determinism_and_state_round_trip():
    env = gym.make("PickClutterYCB-v0", obs_mode="state", reward_mode="normalized_dense")
    obs, info = env.reset(seed=0)
    assert obs.shape == (54,) and obs.dtype == np.float32
    assert env.spec.max_episode_steps == 200
    assert set(info) >= {"success", "is_obj_placed", "is_robot_static"}
    for _ in range(2):
        obs, reward, *_ = env.step(env.action_space.sample())
        assert 0.0 <= reward <= 1.0
    d = gym.make("PickClutterYCB-v0", obs_mode="state_dict", reward_mode="dense")
    a, _ = d.reset(seed=3)
    assert list(a["extra"]) == [
        "tcp_pose",
        "goal_pos",
        "obj_start_pos",
        "tcp_to_goal_pos",
        "obj_pose",
        "tcp_to_obj_pos",
        "obj_to_goal_pos",
    ]
    goal = a["extra"]["goal_pos"]
    assert abs(goal[0]) <= 0.15 and abs(goal[1]) <= 0.25 and 0.35 <= goal[2] <= 0.45
    d.reset(seed=4)
    b, _ = d.reset(seed=3)
    assert_obs_equal(a, b)
    u = d.unwrapped
    u.step(np.zeros(u.action_space.shape, np.float32))
    state = u.get_state()
    before = u.get_obs()
    for _ in range(3):
        u.step(u.action_space.sample())
    u.set_state(state)
    assert_obs_equal(u.get_obs(), before)


def test_clutter_visual_modes_keep_the_start_point():
    env = gym.make("PickClutterYCB-v0", obs_mode="rgbd")
    obs, _ = env.reset(seed=1)
    assert set(obs["extra"]) == {"tcp_pose", "goal_pos", "obj_start_pos"}
    assert obs["image"]["base_camera"]["rgb"].shape == (128, 128, 3)
