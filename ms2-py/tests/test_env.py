"""The single-env gymnasium API: registration, spaces, env checker, seeding, state round trip."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import assert_obs_equal, leaves, make, obs_differs
from gymnasium.utils.env_checker import check_env


def test_import_registers_maniskill2_ids():
    for env_id in ("PickCube-v0", "LiftCube-v0", "StackCube-v0"):
        assert env_id in gym.registry, env_id
        assert env_id in ms2.env_ids()
    assert gym.spec("PickCube-v0").max_episode_steps == 200


def test_make_with_maniskill2_kwargs():
    env = gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    obs, info = env.reset(seed=0)
    assert isinstance(obs, np.ndarray) and obs.dtype == np.float32
    assert obs.shape == env.observation_space.shape == (51,)
    assert env.action_space.shape == (7,)
    assert env.action_space.dtype == np.float32
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert obs in env.observation_space
    assert isinstance(reward, float)
    assert isinstance(terminated, bool) and isinstance(truncated, bool)
    assert info["elapsed_steps"] == 1
    assert "success" in info
    env.close()


def test_state_dict_observation_space_is_dict_of_box():
    env = make("PickCube-v0", obs_mode="state_dict")
    space = env.observation_space
    assert isinstance(space, gym.spaces.Dict)
    assert list(space.keys()) == ["agent", "extra"]
    assert list(space["agent"].keys()) == ["qpos", "qvel", "base_pose"]
    obs, _ = env.reset(seed=1)
    assert obs in space
    flat = make("PickCube-v0", obs_mode="state").reset(seed=1)[0]
    concatenated = np.concatenate([x.ravel() for _, x in leaves(obs)])
    np.testing.assert_array_equal(concatenated, flat)


@pytest.mark.parametrize("obs_mode", ["state", "state_dict"])
def test_env_checker_every_control_mode(env_id, obs_mode):
    control_modes = ms2.Ms2Env(env_id).supported_control_modes
    assert "pd_ee_delta_pose" in control_modes and "pd_joint_delta_pos" in control_modes
    for control_mode in control_modes:
        env = ms2.Ms2Env(env_id, obs_mode=obs_mode, control_mode=control_mode)
        check_env(env, skip_render_check=True)
        env.close()


def test_every_mode_steps(env_id):
    base = ms2.Ms2Env(env_id)
    rng = np.random.default_rng(0)
    for obs_mode in base.supported_obs_modes:
        for control_mode in base.supported_control_modes:
            for reward_mode in base.supported_reward_modes:
                env = ms2.Ms2Env(
                    env_id, obs_mode=obs_mode, control_mode=control_mode, reward_mode=reward_mode
                )
                obs, _ = env.reset(seed=3)
                assert obs in env.observation_space
                space = env.action_space
                for _ in range(3):
                    action = rng.uniform(space.low, space.high).astype(np.float32)
                    obs, reward, *_ = env.step(action)
                    assert obs in env.observation_space, (obs_mode, control_mode)
                    assert np.isfinite(reward), (obs_mode, control_mode, reward_mode)
                if reward_mode == "sparse":
                    assert reward in (0.0, 1.0)
                if reward_mode == "normalized_dense":
                    assert 0.0 <= reward <= 1.0


def test_seeded_resets_are_reproducible(env_id):
    env = make(env_id, obs_mode="state_dict")
    a, _ = env.reset(seed=7)
    b, _ = env.reset(seed=8)
    c, _ = env.reset(seed=7)
    assert_obs_equal(a, c)
    assert obs_differs(a, b)
    # Two envs given the same seed and actions stay identical.
    other = make(env_id, obs_mode="state_dict")
    d, _ = other.reset(seed=7)
    assert_obs_equal(a, d)
    rng = np.random.default_rng(1)
    for _ in range(10):
        action = env.action_space.sample() * 0 + rng.uniform(-1, 1, env.action_space.shape)
        o1, r1, *_ = env.step(action)
        o2, r2, *_ = other.step(action)
        assert_obs_equal(o1, o2)
        assert r1 == r2


def test_unseeded_resets_differ_between_envs():
    a, _ = make("PickCube-v0", obs_mode="state").reset()
    b, _ = make("PickCube-v0", obs_mode="state").reset()
    assert not np.array_equal(a, b)


def test_get_set_state_round_trip(env_id):
    env = make(env_id, obs_mode="state", control_mode="pd_ee_delta_pose")
    env.reset(seed=11)
    rng = np.random.default_rng(2)
    space = env.action_space
    for _ in range(5):
        env.step(rng.uniform(space.low, space.high).astype(np.float32))
    state = env.unwrapped.get_state()
    assert state.dtype == np.float32 and state.ndim == 1
    actions = rng.uniform(space.low, space.high, size=(50, *space.shape)).astype(np.float32)
    first = [env.step(a)[0] for a in actions]
    assert obs_differs(first[0], first[-1])
    env.unwrapped.set_state(state)
    np.testing.assert_array_equal(env.unwrapped.get_state(), state)
    second = [env.step(a)[0] for a in actions]
    for i, (x, y) in enumerate(zip(first, second, strict=True)):
        np.testing.assert_array_equal(x, y, err_msg=f"step {i} after restore")


def test_set_state_rejects_bad_states():
    env = make("PickCube-v0")
    env.reset(seed=0)
    state = env.unwrapped.get_state()
    with pytest.raises(ValueError, match=str(len(state))):
        env.unwrapped.set_state(state[:-1])
    bad = state.copy()
    bad[0] = np.nan
    with pytest.raises(ValueError):
        env.unwrapped.set_state(bad)


def test_max_episode_steps_truncates():
    env = gym.make("PickCube-v0", obs_mode="state", max_episode_steps=5)
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    flags = [env.step(zero)[3] for _ in range(5)]
    assert flags == [False] * 4 + [True]


def test_max_episode_steps_beyond_task_default():
    env = gym.make("PickCube-v0", obs_mode="state", max_episode_steps=230)
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    truncated_at = None
    for step in range(1, 231):
        _, _, terminated, truncated, _ = env.step(zero)
        assert not terminated
        if truncated:
            truncated_at = step
            break
    assert truncated_at == 230


def test_direct_env_truncates_at_task_default():
    env = ms2.Ms2Env("PickCube-v0", obs_mode="state", max_episode_steps=7)
    assert env.max_episode_steps == 7
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    flags = [env.step(zero)[3] for _ in range(7)]
    assert flags[-1] and not any(flags[:-1])
    assert env.elapsed_steps == 7


def test_sim_and_control_freq_kwargs():
    env = ms2.Ms2Env("PickCube-v0", sim_freq=250, control_freq=10)
    assert env.sim_freq == 250 and env.control_freq == 10
    env.reset(seed=0)
    env.step(np.zeros(env.action_space.shape, np.float32))
    with pytest.raises(ValueError, match="multiple"):
        ms2.Ms2Env("PickCube-v0", sim_freq=500, control_freq=30)
