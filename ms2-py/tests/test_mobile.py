"""ManiSkill2's mobile-manipulation tasks on the mobile Pandas: OpenCabinetDrawer-v1 and
OpenCabinetDoor-v1 through the gymnasium API (ManiSkill2's obs dims and mode names,
determinism, get/set_state, the visual modes' layout)."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import assert_obs_equal

CABINETS = ["OpenCabinetDrawer-v1", "OpenCabinetDoor-v1"]
#: ManiSkill2's state dim: agent 26 (qpos 10, qvel 10, base_pos 2, base_orientation 1,
#: base_vel 2, base_ang_vel 1) + articulations 29 + fingers_pos 6 + fingers_vel 6 +
#: target_indicator 8.
STATE_DIM = 75


@pytest.mark.parametrize("env_id", CABINETS)
def test_defaults_modes_and_state_dims_match_maniskill2(env_id):
    env = gym.make(env_id)
    u = env.unwrapped
    assert u.robot == "mobile_panda_single_arm"
    assert u.control_mode == "base_pd_joint_vel_arm_pd_joint_vel"
    assert "base_pd_joint_vel_arm_pd_ee_delta_pose" in u.supported_control_modes
    assert len(u.supported_control_modes) == 10
    assert env.action_space.shape == (12,)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (STATE_DIM,)
    ee = gym.make(env_id, control_mode="base_pd_joint_vel_arm_pd_ee_delta_pose")
    assert ee.action_space.shape == (4 + 6 + 1,)
    sd = gym.make(env_id, obs_mode="state_dict").reset(seed=0)[0]
    assert list(sd["agent"]) == [
        "qpos",
        "qvel",
        "base_pos",
        "base_orientation",
        "base_vel",
        "base_ang_vel",
    ]
    assert list(sd["extra"]) == ["articulations", "fingers_pos", "fingers_vel", "target_indicator"]


def test_unknown_mode_names_the_mobile_modes():
    with pytest.raises(ValueError, match="base_pd_joint_vel_arm_pd_joint_vel"):
        gym.make("OpenCabinetDrawer-v1", control_mode="pd_ee_delta_pose")


def test_same_seed_same_episode_and_state_round_trip():
    a = gym.make("OpenCabinetDoor-v1")
    b = gym.make("OpenCabinetDoor-v1")
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, size=(5, 12)).astype(np.float32)
    oa, _ = a.reset(seed=11)
    ob, _ = b.reset(seed=11)
    assert_obs_equal(oa, ob)
    for act in actions:
        oa = a.step(act)[0]
        ob = b.step(act)[0]
    assert_obs_equal(oa, ob)
    state = a.unwrapped.get_state()
    for act in actions:
        a.step(act)
    a.unwrapped.set_state(state)
    np.testing.assert_allclose(a.unwrapped.get_obs(), ob, atol=1e-4)


def test_scripted_oracle_opens_a_drawer():
    env = gym.make("OpenCabinetDrawer-v1")
    policy = ms2.ScriptedPolicy(env)
    successes = 0
    for seed in range(2):
        env.reset(seed=seed)
        policy.reset()
        while True:
            _, reward, terminated, truncated, info = env.step(policy.act())
            if terminated or truncated:
                break
        successes += bool(info["success"])
    assert successes >= 1


def test_pointcloud_fuses_the_three_overhead_cameras():
    env = gym.make("OpenCabinetDrawer-v1", obs_mode="pointcloud")
    obs, _ = env.reset(seed=0)
    assert obs["pointcloud"]["xyzw"].shape == (3 * 400 * 160, 4)
    assert obs["agent"]["base_pose"].shape == (7,)
    assert sorted(obs["extra"]) == sorted(
        ["target_angle_diff", "target_joint_axis", "target_link_pos", "tcp_pose"]
    )
