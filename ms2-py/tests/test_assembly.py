"""The assembly tasks (PegInsertionSide-v0, PlugCharger-v0, AssemblingKits-v0) under ManiSkill2's
ids and layouts."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import leaves

ASSEMBLY = {
    "PegInsertionSide-v0": (
        50,
        [
            "/extra/tcp_pose",
            "/extra/peg_pose",
            "/extra/peg_half_size",
            "/extra/box_hole_pose",
            "/extra/box_hole_radius",
        ],
        25.0,
    ),
    "PlugCharger-v0": (
        53,
        ["/extra/tcp_pose", "/extra/charger_pose", "/extra/receptacle_pose", "/extra/goal_pose"],
        50.0,
    ),
    "AssemblingKits-v0": (
        51,
        [
            "/extra/tcp_pose",
            "/extra/obj_init_pos",
            "/extra/obj_goal_pos",
            "/extra/obj_pose",
            "/extra/tcp_to_obj_pos",
            "/extra/obj_to_goal_pos",
        ],
        10.0,
    ),
}

#: The `extra` keys of the visual obs modes (ManiSkill2's: what is not privileged).
VISUAL_EXTRA = {
    "PegInsertionSide-v0": ["tcp_pose"],
    "PlugCharger-v0": ["tcp_pose"],
    "AssemblingKits-v0": ["tcp_pose", "obj_init_pos", "obj_goal_pos"],
}


@pytest.mark.parametrize("env_id", sorted(ASSEMBLY))
def test_registered_with_maniskill2_layout(env_id):
    size, extra_keys, _ = ASSEMBLY[env_id]
    assert env_id in ms2.env_ids()
    assert gym.spec(env_id).max_episode_steps == 200
    env = gym.make(env_id)
    assert env.unwrapped.control_mode == "pd_joint_delta_pos"
    assert env.observation_space.shape == (size,)
    obs, info = env.reset(seed=0)
    assert obs.shape == (size,) and obs.dtype == np.float32
    assert info["success"] is False or info["success"] == np.False_
    sd = gym.make(env_id, obs_mode="state_dict").reset(seed=0)[0]
    paths = [p for p, _ in leaves(sd)]
    assert paths == ["/agent/qpos", "/agent/qvel", "/agent/base_pose", *extra_keys]
    np.testing.assert_array_equal(obs, np.concatenate([x for _, x in leaves(sd)]))


def test_peg_and_hole_are_drawn_per_episode():
    env = gym.make("PegInsertionSide-v0", obs_mode="state_dict")
    sizes = []
    for seed in (0, 1, 2, 0):
        extra = env.reset(seed=seed)[0]["extra"]
        half = extra["peg_half_size"]
        assert 0.075 <= half[0] <= 0.125 and 0.015 <= half[1] <= 0.025
        assert half[1] == half[2]
        # The hole is the peg plus 3 mm on each side.
        np.testing.assert_allclose(extra["box_hole_radius"][0], half[1] + 0.003, atol=1e-6)
        sizes.append(half.copy())
    assert not np.allclose(sizes[0], sizes[1]) and not np.allclose(sizes[1], sizes[2])
    np.testing.assert_array_equal(sizes[0], sizes[3])


@pytest.mark.parametrize("env_id", sorted(ASSEMBLY))
def test_same_seed_same_episode_and_state_round_trip(env_id):
    a, b = gym.make(env_id), gym.make(env_id)
    oa, _ = a.reset(seed=3)
    ob, _ = b.reset(seed=3)
    np.testing.assert_array_equal(oa, ob)
    rng = np.random.default_rng(0)
    for _ in range(5):
        act = rng.uniform(-1, 1, a.action_space.shape).astype(np.float32)
        oa, ra, *_ = a.step(act)
        ob, rb, *_ = b.step(act)
    np.testing.assert_array_equal(oa, ob)
    assert ra == rb
    state = a.unwrapped.get_state()
    a.step(np.zeros(a.action_space.shape, np.float32))
    a.unwrapped.set_state(state)
    np.testing.assert_array_equal(a.unwrapped.get_obs(), oa)


@pytest.mark.parametrize("env_id", sorted(ASSEMBLY))
def test_scripted_policy_succeeds_and_rewards_stay_in_range(env_id):
    _, _, max_dense = ASSEMBLY[env_id]
    env = gym.make(env_id, control_mode="pd_ee_delta_pose", reward_mode="dense")
    policy = ms2.ScriptedPolicy(env)
    env.reset(seed=0)
    policy.reset()
    rewards = []
    for _ in range(200):
        _, reward, terminated, truncated, info = env.step(policy.act())
        rewards.append(reward)
        if terminated or truncated:
            break
    assert info["success"], info
    assert rewards[-1] == max_dense
    assert all(np.isfinite(rewards)) and max(rewards) <= max_dense
    # The shaped reward rises as the task progresses.
    assert np.mean(rewards[-10:]) > np.mean(rewards[:10])


@pytest.mark.parametrize("env_id", sorted(ASSEMBLY))
def test_rgbd_keeps_only_unprivileged_extras(env_id):
    env = gym.make(env_id, obs_mode="rgbd")
    obs, _ = env.reset(seed=0)
    assert list(obs["extra"]) == VISUAL_EXTRA[env_id]
    for cam in ("base_camera", "hand_camera"):
        assert obs["image"][cam]["rgb"].shape == (128, 128, 3)
        assert obs["image"][cam]["depth"].shape == (128, 128, 1)
    # The task's parts are in view of the base camera: not all one colour.
    assert obs["image"]["base_camera"]["rgb"].std() > 5


def test_make_vec_batches_assembly_envs():
    envs = ms2.make_vec("PegInsertionSide-v0", num_envs=2)
    obs, _ = envs.reset(seed=0)
    assert obs.shape == (2, 50)
    # Env i is seeded with seed + i: the two pegs differ.
    assert not np.allclose(obs[0, 39:42], obs[1, 39:42])
    obs, reward, terminated, truncated, _ = envs.step(
        np.zeros((2, *envs.single_action_space.shape), np.float32)
    )
    assert obs.shape == (2, 50) and reward.shape == (2,)
    envs.close()


def test_kits_shape_lands_in_its_slot():
    # Seed 2: seed 1, used until 2026-11-24, is one of the scripted policy's failures since the
    # fingers' torsional friction (10/12 of seeds 0-11 in pd_joint_delta_pos, docs/tasks.md).
    env = gym.make("AssemblingKits-v0", obs_mode="state_dict")
    policy = ms2.ScriptedPolicy(env)
    extra = env.reset(seed=2)[0]["extra"]
    policy.reset()
    # The shape starts on the ground, away from its slot in the board.
    assert np.linalg.norm(extra["obj_pose"][:2] - extra["obj_goal_pos"][:2]) > 0.05
    for _ in range(200):
        obs, _, terminated, _, info = env.step(policy.act())
        if terminated:
            break
    assert info["success"] and info["in_slot"] and info["rot_correct"], info
    # Down in the slot: its bottom below 3 mm, at the slot's xy.
    assert obs["extra"]["obj_pose"][2] < 0.003
    assert np.linalg.norm(obs["extra"]["obj_to_goal_pos"][:2]) < 0.02


@pytest.mark.parametrize("mode", ["pd_joint_pos", "pd_joint_delta_pos", "pd_ee_delta_pose"])
def test_kits_take_the_xmate3(mode):
    # ManiSkill2's AssemblingKits is a StationaryManipulationEnv: the Panda or the xMate3.
    panda = gym.make("AssemblingKits-v0", obs_mode="state_dict")
    env = gym.make("AssemblingKits-v0", robot="xmate3_robotiq", control_mode=mode)
    assert env.unwrapped.robot == "xmate3_robotiq"
    obs, _ = env.reset(seed=2)
    assert obs.shape == (51,)  # both robots have 9 joints: the Panda's layout
    sd = env.unwrapped.get_obs()
    start = gym.make("AssemblingKits-v0", robot="xmate3_robotiq", obs_mode="state_dict")
    x_extra = start.reset(seed=2)[0]["extra"]
    p_extra = panda.reset(seed=2)[0]["extra"]
    # Same kit and shape for the same seed, whichever robot.
    np.testing.assert_array_equal(x_extra["obj_goal_pos"], p_extra["obj_goal_pos"])
    np.testing.assert_array_equal(x_extra["obj_init_pos"], p_extra["obj_init_pos"])
    rng = np.random.default_rng(0)
    for _ in range(5):
        act = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, reward, terminated, truncated, info = env.step(act)
        assert np.isfinite(obs).all() and np.isfinite(reward)
    assert not info["success"]
    assert not np.allclose(obs[:7], sd[:7]), "the arm moved"


def test_kits_cameras_with_the_xmate3():
    # ManiSkill2's agent cameras override the task's: the xMate3's base_camera stays on its
    # mount, the Panda's (a camera in the world) takes the task's view; render() is the task's.
    views = {}
    for robot in ("panda", "xmate3_robotiq"):
        env = gym.make("AssemblingKits-v0", robot=robot, obs_mode="rgbd")
        obs, _ = env.reset(seed=0)
        assert set(obs["image"]) == {"base_camera", "hand_camera"}
        views[robot] = obs["camera_param"]["base_camera"]["cam2world_gl"][:3, 3]
        assert obs["image"]["base_camera"]["rgb"].std() > 5
    np.testing.assert_allclose(views["panda"], [0.2, 0.0, 0.4], atol=1e-5)
    # The xMate3's base camera: 0.965 m in front of its base at x = -0.562, 0.5 m up.
    np.testing.assert_allclose(views["xmate3_robotiq"], [0.403, 0.0, 0.5], atol=1e-3)
