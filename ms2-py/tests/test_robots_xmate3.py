"""ManiSkill2's second robot, ``robot="xmate3_robotiq"``, on the cube tasks: its control modes,
observation dims (ManiSkill2's), cameras, determinism and state round trip."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from conftest import assert_obs_equal, assert_state_round_trip

CUBE_TASKS = {"PickCube-v0": 51, "LiftCube-v0": 42, "StackCube-v0": 55}
XMATE = "xmate3_robotiq"


@pytest.mark.parametrize("env_id", list(CUBE_TASKS))
def test_defaults_and_state_dims_match_maniskill2(env_id):
    env = gym.make(env_id, robot=XMATE)
    u = env.unwrapped
    assert u.robot == XMATE
    # ManiSkill2: the agent's first mode; the xMate3's is pd_joint_pos.
    assert u.control_mode == "pd_joint_pos"
    assert u.supported_control_modes == [
        "pd_joint_pos",
        "pd_joint_delta_pos",
        "pd_ee_delta_pos",
        "pd_ee_delta_pose",
    ]
    assert env.action_space.shape == (8,)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (CUBE_TASKS[env_id],)
    sd = gym.make(env_id, robot=XMATE, obs_mode="state_dict").reset(seed=0)[0]
    assert sd["agent"]["qpos"].shape == (9,)
    np.testing.assert_allclose(sd["agent"]["base_pose"][:3], [-0.562, 0.0, 0.0], atol=1e-6)


@pytest.mark.parametrize(
    "mode,dim",
    [
        ("pd_joint_pos", 8),
        ("pd_joint_delta_pos", 8),
        ("arm_pd_joint_delta_pos", 8),
        ("pd_ee_delta_pos", 4),
        ("pd_ee_delta_pose", 7),
    ],
)
def test_every_control_mode_steps(mode, dim):
    env = gym.make("PickCube-v0", robot=XMATE, control_mode=mode)
    assert env.action_space.shape == (dim,)
    env.reset(seed=1)
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert np.isfinite(obs).all() and np.isfinite(reward)


def test_unsupported_mode_is_a_value_error_listing_the_robot_modes():
    with pytest.raises(ValueError, match="pd_ee_delta_pose"):
        gym.make("PickCube-v0", robot=XMATE, control_mode="pd_joint_vel")


def test_seeded_reset_and_state_round_trip():
    env = gym.make("StackCube-v0", robot=XMATE, obs_mode="state_dict")
    a, _ = env.reset(seed=4)
    for _ in range(3):
        env.step(env.action_space.sample())
    b, _ = env.reset(seed=4)
    assert_obs_equal(a, b)
    for _ in range(3):
        env.step(env.action_space.sample())
    assert_state_round_trip(env)


def test_cameras_ride_on_the_robot():
    env = gym.make("PickCube-v0", robot=XMATE, obs_mode="rgbd")
    obs, _ = env.reset(seed=0)
    assert set(obs["image"]) == {"base_camera", "hand_camera"}
    for cam in obs["image"].values():
        assert cam["rgb"].shape == (128, 128, 3)
    hand_before = obs["camera_param"]["hand_camera"]["cam2world_gl"].copy()
    base_before = obs["camera_param"]["base_camera"]["cam2world_gl"].copy()
    for _ in range(5):
        # pd_joint_pos: every arm joint towards 0.3 rad.
        obs, *_ = env.step(np.full(8, 0.3, dtype=np.float32))
    # The wrist camera moves with the arm; the base camera is fixed on the robot's base.
    assert not np.allclose(obs["camera_param"]["hand_camera"]["cam2world_gl"], hand_before)
    np.testing.assert_allclose(obs["camera_param"]["base_camera"]["cam2world_gl"], base_before)


# ManiSkill2 0.5.3 builds every StationaryManipulationEnv with either robot; its own test_robots
# skips only PandaAvoidObstacles, PegInsertionSide, PickClutterYCB, TurnFaucet and mobile tasks.
OTHER_STATIONARY_TASKS = ["PickSingleYCB-v0", "PickSingleEGAD-v0", "PlugCharger-v0"]


@pytest.mark.parametrize("env_id", OTHER_STATIONARY_TASKS)
def test_other_stationary_tasks_take_the_xmate3(env_id):
    panda_obs, _ = gym.make(env_id).reset(seed=0)
    env = gym.make(env_id, robot=XMATE)
    assert env.unwrapped.robot == XMATE and env.action_space.shape == (8,)
    obs, _ = env.reset(seed=0)
    assert obs.shape == panda_obs.shape  # both robots have 9 joints: the same layout
    tcp_start = env.unwrapped.get_obs()
    for _ in range(5):
        obs, reward, *_ = env.step(env.action_space.sample())
        assert np.isfinite(obs).all() and np.isfinite(reward)
    before = assert_state_round_trip(env, steps_after=3)
    assert not np.allclose(tcp_start, before), "the arm moved"
    env.close()


@pytest.mark.parametrize("env_id", ["PegInsertionSide-v0", "PickClutterYCB-v0"])
def test_panda_only_tasks_refuse_the_xmate3(env_id):
    with pytest.raises(ValueError, match="panda"):
        gym.make(env_id, robot=XMATE)
