"""ManiSkill2's rigid tasks under their ManiSkill2 ids, layouts and controllers."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import leaves

MANISKILL2_IDS = ["PickCube-v0", "LiftCube-v0", "StackCube-v0"]


@pytest.mark.parametrize("env_id", MANISKILL2_IDS)
def test_registered_with_maniskill2_defaults(env_id):
    assert env_id in ms2.env_ids()
    assert gym.spec(env_id).max_episode_steps == 200
    env = gym.make(env_id)
    unwrapped = env.unwrapped
    assert unwrapped.obs_mode == "state"  # ManiSkill2's SUPPORTED_OBS_MODES[0]
    assert unwrapped.control_mode == "pd_joint_delta_pos"
    assert unwrapped.reward_mode == "normalized_dense"
    assert env.action_space.shape == (8,)
    for mode in ("pd_joint_delta_pos", "pd_ee_delta_pose", "pd_ee_delta_pos", "pd_joint_pos"):
        assert mode in unwrapped.supported_control_modes


def test_pick_cube_state_layout():
    env = gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    assert env.observation_space.shape == (51,)
    assert env.action_space.shape == (7,)
    np.testing.assert_allclose(env.action_space.high[:6], 1.0)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (51,)
    sd = gym.make("PickCube-v0", obs_mode="state_dict").reset(seed=0)[0]
    assert [path for path, _ in leaves(sd)] == [
        "/agent/qpos",
        "/agent/qvel",
        "/agent/base_pose",
        "/extra/tcp_pose",
        "/extra/goal_pos",
        "/extra/tcp_to_goal_pos",
        "/extra/obj_pose",
        "/extra/tcp_to_obj_pos",
        "/extra/obj_to_goal_pos",
    ]
    # The Panda base stands at (-0.615, 0, 0).
    np.testing.assert_allclose(sd["agent"]["base_pose"][:3], [-0.615, 0.0, 0.0], atol=1e-6)
    np.testing.assert_array_equal(obs, np.concatenate([x for _, x in leaves(sd)]))
