"""Hang-v0 from Python: the rope's particles, the rod, info terms, states, vector envs."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np


def test_hang_resets_with_the_rope_and_the_rod_and_steps():
    env = gym.make("Hang-v0", obs_mode="particles")
    assert env.unwrapped.mpm_freq == 4000.0
    obs, _ = env.reset(seed=0)
    x = obs["particles"]["x"]
    assert x.dtype == np.float32 and x.ndim == 2 and x.shape[1] == 3 and x.shape[0] > 9000
    assert x[:, 2].min() >= 0.0 and x[:, 2].max() < 0.2  # on the fingertips and the ground
    target = obs["extra"]["target"]
    assert target.shape == (7,)
    assert 0.2 <= np.hypot(target[0], target[1]) <= 0.23 and 0.2 <= target[2] <= 0.3
    obs, reward, terminated, _, info = env.step(np.zeros(env.action_space.shape, np.float32))
    assert obs["particles"]["x"].shape == x.shape
    assert {"success", "sides", "over_rod", "ends_down", "off_ground"} <= set(info)
    assert not info["success"] and not terminated and 0.0 <= reward <= 6.0
    state = env.unwrapped.get_state()
    env.step(np.zeros(env.action_space.shape, np.float32))
    env.unwrapped.set_state(state)
    np.testing.assert_array_equal(env.unwrapped.get_state()[13:], state[13:])
    env.close()


def test_hang_vector_envs_draw_their_own_rods():
    envs = ms2.make_vec("Hang-v0", num_envs=2, obs_mode="state_dict")
    obs, _ = envs.reset(seed=[3, 4])
    rods = obs["extra"]["target"]
    assert rods.shape == (2, 7) and not np.array_equal(rods[0], rods[1])
    envs.close()
