"""The single-env gymnasium API: registration, spaces, env checker, seeding, state round trip."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import (
    ENV_IDS,
    HEAVY,
    MAIN_ID,
    SLOWEST_SOFT,
    SOFT_TASKS,
    assert_obs_equal,
    leaves,
    make,
    obs_differs,
    preferred_control_mode,
    random_actions,
    sweeps_every_combination,
)
from gymnasium.utils.env_checker import check_env


def test_import_registers_every_task():
    assert ENV_IDS
    for env_id in ENV_IDS:
        spec = gym.spec(env_id)
        assert spec.max_episode_steps == ms2.Ms2Env(env_id).max_episode_steps
        assert spec.vector_entry_point == "ms2.vector:make_vec"


def test_make_returns_numpy_and_python_scalars(env_id):
    env = gym.make(env_id, obs_mode="state", control_mode=preferred_control_mode(env_id))
    obs, info = env.reset(seed=0)
    assert isinstance(obs, np.ndarray) and obs.dtype == np.float32
    assert obs.shape == env.observation_space.shape
    assert env.action_space.dtype == np.float32
    assert np.all(env.action_space.low < env.action_space.high)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert obs in env.observation_space
    assert isinstance(reward, float)
    assert isinstance(terminated, bool) and isinstance(truncated, bool)
    assert info["elapsed_steps"] == 1
    assert isinstance(info["success"], bool)
    env.close()


def test_state_dict_is_dict_of_box_in_layout_order(env_id):
    env = make(env_id, obs_mode="state_dict")
    space = env.observation_space
    assert isinstance(space, gym.spaces.Dict)
    assert list(space.keys()) == ["agent", "extra"]
    assert list(space["agent"].keys())[:2] == ["qpos", "qvel"]
    assert all(isinstance(sub, gym.spaces.Box) for sub in _space_leaves(space))
    obs, _ = env.reset(seed=1)
    assert obs in space
    # The flat `state` observation is the state_dict's leaves concatenated in layout order.
    flat = make(env_id, obs_mode="state").reset(seed=1)[0]
    concatenated = np.concatenate([x.ravel() for _, x in leaves(obs)])
    np.testing.assert_array_equal(concatenated, flat)
    np.testing.assert_array_equal(gym.spaces.flatten(space, obs), flat)


def _space_leaves(space):
    if isinstance(space, gym.spaces.Dict):
        for sub in space.values():
            yield from _space_leaves(sub)
    else:
        yield space


@pytest.mark.parametrize("obs_mode", ["state", "state_dict"])
def test_env_checker_every_control_mode(env_id, obs_mode):
    base = ms2.Ms2Env(env_id)
    control_modes = base.supported_control_modes
    if not sweeps_every_combination(env_id):
        # test_every_obs_control_and_reward_mode_steps steps every control mode of these.
        control_modes = [base.control_mode]
    for control_mode in control_modes:
        env = ms2.Ms2Env(env_id, obs_mode=obs_mode, control_mode=control_mode)
        check_env(env, skip_render_check=True)
        env.close()


def test_every_obs_control_and_reward_mode_steps(env_id):
    base = ms2.Ms2Env(env_id)
    rng = np.random.default_rng(0)
    # State modes here; the visual modes have their own tests (test_visual.py).
    state_modes = [m for m in base.supported_obs_modes if m in ("state", "state_dict", "none")]
    assert state_modes == ["state", "state_dict", "none"]
    combinations = [
        (obs_mode, control_mode, reward_mode)
        for obs_mode in state_modes
        for control_mode in base.supported_control_modes
        for reward_mode in base.supported_reward_modes
    ]
    steps = 3
    if not sweeps_every_combination(env_id):
        # Soft-body envs step their MPM for seconds per env step (Write-v0: 17,640 particles)
        # and the clutter takes seconds to build: every control mode once and every obs and
        # reward mode once, not their product (the modes' plumbing is the runtime's, shared
        # with the tasks swept in full above); soft envs one step each.
        steps = 1 if env_id in SOFT_TASKS else 3
        default_control = base.control_mode
        combinations = [("state", c, "normalized_dense") for c in base.supported_control_modes]
        combinations += [
            (o, default_control, r)
            for o in state_modes
            for r in base.supported_reward_modes
            if (o, r) != ("state", "normalized_dense")
        ]
        if env_id in SLOWEST_SOFT and not HEAVY:
            # Seconds per step: the other obs and reward modes once each, not their product.
            combinations = combinations[: len(base.supported_control_modes)] + [
                ("state_dict", default_control, "dense"),
                ("none", default_control, "sparse"),
            ]
    for obs_mode, control_mode, reward_mode in combinations:
        env = ms2.Ms2Env(
            env_id, obs_mode=obs_mode, control_mode=control_mode, reward_mode=reward_mode
        )
        assert (env.obs_mode, env.control_mode, env.reward_mode) == (
            obs_mode,
            control_mode,
            reward_mode,
        )
        obs, _ = env.reset(seed=3)
        assert obs in env.observation_space
        for action in random_actions(env.action_space, rng, steps):
            obs, reward, *_ = env.step(action)
            assert obs in env.observation_space, (obs_mode, control_mode)
            assert np.isfinite(reward), (obs_mode, control_mode, reward_mode)
            if reward_mode == "sparse":
                assert reward in (0.0, 1.0)
            if reward_mode == "normalized_dense":
                # ManiSkill2's assembly rewards subtract penalties before a grasp: they
                # go below 0 (never above 1).
                low = -np.inf if env_id in PENALISED_REWARDS else 0.0
                assert low <= reward <= 1.0


#: Tasks whose ManiSkill2 dense reward can be negative.
PENALISED_REWARDS = {
    "PegInsertionSide-v0",
    "PlugCharger-v0",
    "OpenCabinetDrawer-v1",
    "OpenCabinetDoor-v1",
    "PushChair-v1",
    "MoveBucket-v1",
    "Pinch-v0",
    "Pour-v0",
}


def test_seeded_resets_are_reproducible(env_id):
    env = make(env_id, obs_mode="state_dict")
    a, _ = env.reset(seed=7)
    b, _ = env.reset(seed=8)
    c, _ = env.reset(seed=7)
    assert_obs_equal(a, c)
    assert obs_differs(a, b)
    # Two envs given the same seed and actions stay identical.
    other = make(env_id, obs_mode="state_dict")
    assert_obs_equal(a, other.reset(seed=7)[0])
    steps = 3 if env_id in SOFT_TASKS else 10
    for action in random_actions(env.action_space, np.random.default_rng(1), steps):
        o1, r1, *_ = env.step(action)
        o2, r2, *_ = other.step(action)
        assert_obs_equal(o1, o2)
        assert r1 == r2


def test_unseeded_resets_differ_between_envs():
    a, _ = make(obs_mode="state").reset()
    b, _ = make(obs_mode="state").reset()
    assert not np.array_equal(a, b)


def test_get_set_state_round_trip(env_id):
    env = make(env_id, obs_mode="state", control_mode=preferred_control_mode(env_id))
    env.reset(seed=11)
    rng = np.random.default_rng(2)
    quick = env_id in SLOWEST_SOFT and not HEAVY
    for action in random_actions(env.action_space, rng, 2 if quick else 5):
        env.step(action)
    state = env.unwrapped.get_state()
    assert state.dtype == np.float32 and state.ndim == 1
    # 50 steps after the restore; 8 for the soft tasks, 3 for the slowest without
    # MS2_HEAVY_TESTS (seconds per step; their Rust tests step restores further).
    after = 3 if quick else 8 if env_id in SOFT_TASKS else 50
    actions = random_actions(env.action_space, rng, after)
    first = [env.step(a)[0] for a in actions]
    assert obs_differs(first[0], first[-1])
    env.unwrapped.set_state(state)
    np.testing.assert_array_equal(env.unwrapped.get_state(), state)
    second = [env.step(a)[0] for a in actions]
    for i, (x, y) in enumerate(zip(first, second, strict=True)):
        np.testing.assert_array_equal(x, y, err_msg=f"step {i} after restore")


def test_set_state_rejects_bad_states():
    env = make()
    env.reset(seed=0)
    state = env.unwrapped.get_state()
    with pytest.raises(ValueError, match=str(len(state))):
        env.unwrapped.set_state(state[:-1])
    bad = state.copy()
    bad[0] = np.nan
    with pytest.raises(ValueError):
        env.unwrapped.set_state(bad)


def _truncation_step(env, limit):
    zero = np.zeros(env.action_space.shape, np.float32)
    for step in range(1, limit + 1):
        _, _, terminated, truncated, _ = env.step(zero)
        assert not terminated
        if truncated:
            return step
    return None


def test_gymnasium_max_episode_steps_truncates():
    env = gym.make(MAIN_ID, obs_mode="state", max_episode_steps=5)
    env.reset(seed=0)
    assert _truncation_step(env, 5) == 5


def test_gymnasium_max_episode_steps_beyond_task_default():
    default = gym.spec(MAIN_ID).max_episode_steps
    env = gym.make(MAIN_ID, obs_mode="state", max_episode_steps=default + 30)
    env.reset(seed=0)
    assert _truncation_step(env, default + 30) == default + 30


def test_direct_env_truncates_itself():
    env = ms2.Ms2Env(MAIN_ID, obs_mode="state", max_episode_steps=7)
    assert env.max_episode_steps == 7
    env.reset(seed=0)
    assert _truncation_step(env, 7) == 7
    assert env.elapsed_steps == 7


def test_sim_and_control_freq_kwargs():
    env = ms2.Ms2Env(MAIN_ID, sim_freq=250, control_freq=10)
    assert env.sim_freq == 250 and env.control_freq == 10
    assert env.metadata["render_fps"] == 10
    env.reset(seed=0)
    env.step(np.zeros(env.action_space.shape, np.float32))
    with pytest.raises(ValueError, match="multiple"):
        ms2.Ms2Env(MAIN_ID, sim_freq=500, control_freq=30)
