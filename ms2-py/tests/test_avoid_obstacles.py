"""``PandaAvoidObstacles-v0``: ManiSkill2's id, limit, observation layout, rewards, seeding,
state round trip, the scripted (planned) policy and the visual modes."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import assert_obs_equal, assert_state_round_trip, leaves

ENV_ID = "PandaAvoidObstacles-v0"


def test_registered_with_maniskill2_facts():
    assert ENV_ID in ms2.env_ids()
    assert gym.spec(ENV_ID).max_episode_steps == 500
    env = gym.make(ENV_ID)
    assert env.unwrapped.control_mode == "pd_joint_delta_pos"
    obs, info = env.reset(seed=0)
    assert obs.shape == (39,)
    assert not info["success"] and info["pos_dist"] > 0.025
    sd = gym.make(ENV_ID, obs_mode="state_dict").reset(seed=0)[0]
    assert [p for p, _ in leaves(sd)] == [
        "/agent/qpos",
        "/agent/qvel",
        "/agent/base_pose",
        "/extra/tcp_pose",
        "/extra/goal_pose",
    ]
    np.testing.assert_allclose(sd["agent"]["base_pose"], [0, 0, 0, 1, 0, 0, 0], atol=1e-6)


def test_episodes_follow_the_seed_and_state_round_trips():
    env = gym.make(ENV_ID, obs_mode="state_dict")
    a, _ = env.reset(seed=11)
    b, _ = env.reset(seed=12)
    assert not np.array_equal(a["extra"]["goal_pose"], b["extra"]["goal_pose"])
    again, _ = env.reset(seed=11)
    assert_obs_equal(a, again)
    for _ in range(3):
        env.step(env.action_space.sample())
    assert_state_round_trip(env)


def test_scripted_policy_reaches_the_goal_with_bounded_rewards():
    env = gym.make(ENV_ID, reward_mode="normalized_dense")
    env.reset(seed=3)
    policy = ms2.ScriptedPolicy(env)
    policy.reset()
    rewards, success = [], False
    for _ in range(120):
        _, reward, terminated, truncated, info = env.step(policy.act())
        rewards.append(reward)
        if terminated:
            success = info["success"]
            break
    assert success
    assert max(rewards) <= 1.0 + 1e-9
    assert rewards[-1] == pytest.approx(1.0)


@pytest.mark.parametrize("obs_mode", ["rgbd", "pointcloud"])
def test_visual_modes_see_the_obstacles(obs_mode):
    env = gym.make(ENV_ID, obs_mode=obs_mode)
    obs, _ = env.reset(seed=0)
    assert set(obs["extra"]) == {"tcp_pose", "goal_pose"}
    if obs_mode == "rgbd":
        rgb = obs["image"]["base_camera"]["rgb"].reshape(-1, 3).astype(int)
        # The white wall fills part of the base camera's view, the coloured obstacles some more.
        assert (rgb.min(axis=1) > 150).mean() > 0.05
        assert ((rgb.max(axis=1) - rgb.min(axis=1)) > 80).mean() > 0.001
    else:
        assert obs["pointcloud"]["xyzw"].shape[1] == 4


def test_make_vec_steps_every_env():
    venv = ms2.make_vec(ENV_ID, num_envs=2)
    obs, _ = venv.reset(seed=[0, 1])
    assert obs.shape == (2, 39)
    obs, reward, terminated, truncated, info = venv.step(venv.action_space.sample())
    assert obs.shape == (2, 39) and np.isfinite(reward).all()
    venv.close()
