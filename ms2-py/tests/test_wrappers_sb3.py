"""ms2.wrappers' stable-baselines3 parts: ContinuousTaskWrapper, SuccessInfoWrapper and the
VecEnv adapter over make_vec (its bookkeeping tested without stable-baselines3; the real
stable-baselines3 base class only where the package is installed)."""

from __future__ import annotations

import importlib.util
import sys

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import MAIN_ID
from ms2.wrappers import ContinuousTaskWrapper, SB3VecEnvAdapter, SuccessInfoWrapper
from ms2.wrappers.sb3_vec_env import index_obs, split_vector_info

HAVE_SB3 = importlib.util.find_spec("stable_baselines3") is not None


def _scripted_episode(env, seed=0):
    """Steps the scripted policy until the episode ends; returns the per-step tuples."""
    policy = ms2.ScriptedPolicy(env)
    env.reset(seed=seed)
    policy.reset()
    steps = []
    while True:
        out = env.step(policy.act())
        steps.append(out)
        if out[2] or out[3]:
            return steps


def test_continuous_task_wrapper_never_terminates_only_truncates():
    limit = 60
    make = dict(control_mode="pd_ee_delta_pose", max_episode_steps=limit)
    plain = _scripted_episode(gym.make(MAIN_ID, **make))
    assert plain[-1][2] and plain[-1][4]["success"], "the scripted episode must succeed"
    assert len(plain) < limit
    steps = _scripted_episode(ContinuousTaskWrapper(gym.make(MAIN_ID, **make)))
    assert len(steps) == limit  # ran on past the success up to the time limit
    assert not any(terminated for _, _, terminated, _, _ in steps)
    assert steps[-1][3]  # truncated
    assert steps[len(plain) - 1][4]["success"]  # success still reported in info


def test_success_info_wrapper_copies_success():
    env = SuccessInfoWrapper(gym.make(MAIN_ID, control_mode="pd_ee_delta_pose"))
    steps = _scripted_episode(env)
    assert all(info["is_success"] == info["success"] for *_, info in steps)
    assert steps[-1][4]["is_success"]


def test_split_vector_info_and_index_obs():
    info = {
        "a": np.array([1, 2, 3]),
        "_a": np.array([True, False, True]),
        "nested": {"b": np.array([4.0, 5.0, 6.0])},
        "_nested": np.array([False, True, True]),
    }
    per_env = split_vector_info(info, 3)
    assert per_env == [{"a": 1}, {"nested": {"b": 5.0}}, {"a": 3, "nested": {"b": 6.0}}]
    obs = {"x": np.arange(6).reshape(3, 2), "y": {"z": np.arange(3)}}
    picked = index_obs(obs, 1)
    np.testing.assert_array_equal(picked["x"], [2, 3])
    obs["x"][1, 0] = 99  # a copy, not a view
    assert picked["x"][0] == 2 and picked["y"]["z"] == 1


def _actions(space, steps, num_envs, seed=0):
    rng = np.random.default_rng(seed)
    shape = (steps, num_envs, *space.shape)
    return rng.uniform(space.low, space.high, size=shape).astype(np.float32)


def test_adapter_same_step_autoreset_matches_make_vec():
    """The adapter resets finished envs within the step: its observations equal the native
    vector env's after that env's next-step autoreset, and no action is lost to a reset."""
    n, limit, steps = 2, 4, 11
    kwargs = dict(control_mode="pd_ee_delta_pose", max_episode_steps=limit)
    adapter = SB3VecEnvAdapter(ms2.make_vec(MAIN_ID, num_envs=n, **kwargs))
    raw = ms2.make_vec(MAIN_ID, num_envs=n, **kwargs)
    actions = _actions(adapter.action_space, steps, n)
    assert adapter.seed(5) == [5, 6]
    obs = adapter.reset()
    raw_obs, _ = raw.reset(seed=5)
    np.testing.assert_array_equal(obs, raw_obs)
    assert [info["elapsed_steps"] for info in adapter.reset_infos] == [0, 0]
    for t in range(steps):
        obs, rewards, dones, infos = adapter.step(actions[t])
        raw_obs, raw_rewards, terminated, truncated, _ = raw.step(actions[t])
        assert rewards.dtype == np.float32 and dones.dtype == np.bool_
        np.testing.assert_array_equal(dones, terminated | truncated)
        np.testing.assert_allclose(rewards, raw_rewards.astype(np.float32))
        # Every step is a real step: episodes are exactly `limit` steps long.
        expect_done = (t + 1) % limit == 0
        assert dones.tolist() == [expect_done] * n
        for i in range(n):
            assert infos[i]["TimeLimit.truncated"] == bool(truncated[i] and not terminated[i])
            assert infos[i]["elapsed_steps"] == t % limit + 1
        if expect_done:
            for i in range(n):
                np.testing.assert_array_equal(infos[i]["terminal_observation"], raw_obs[i])
            assert [info["elapsed_steps"] for info in adapter.reset_infos] == [0, 0]
            raw_obs, *_ = raw.step(actions[t])  # the native autoreset step (action ignored)
        else:
            assert "terminal_observation" not in infos[0]
        np.testing.assert_array_equal(obs, raw_obs)
    adapter.close()
    raw.close()


def test_adapter_reset_is_seeded_once_and_reproducible():
    adapter = SB3VecEnvAdapter(ms2.make_vec(MAIN_ID, num_envs=2))
    adapter.seed(3)
    first = adapter.reset()
    second = adapter.reset()  # unseeded: continues each env's sequence
    adapter.seed(3)
    again = adapter.reset()
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, second)
    adapter.close()


def test_adapter_attributes_methods_and_errors():
    venv = ms2.make_vec(MAIN_ID, num_envs=3, control_mode="pd_joint_delta_pos")
    adapter = SB3VecEnvAdapter(venv)
    assert adapter.num_envs == 3
    assert adapter.observation_space == venv.single_observation_space
    assert adapter.action_space == venv.single_action_space
    adapter.reset()
    assert adapter.get_attr("control_mode") == ["pd_joint_delta_pos"] * 3
    assert adapter.get_attr("control_mode", indices=1) == ["pd_joint_delta_pos"]
    states = adapter.env_method("get_state", indices=[2, 0])
    np.testing.assert_array_equal(states[0], venv.get_state(2))
    np.testing.assert_array_equal(states[1], venv.get_state(0))
    assert adapter.env_is_wrapped(gym.Wrapper) == [False] * 3
    with pytest.raises(ValueError, match=r"indices must be in \[0, 2\], got \[3\]"):
        adapter.get_attr("control_mode", indices=[3])
    with pytest.raises(ValueError, match="all 3 envs only"):
        adapter.set_attr("foo", 1, indices=[0])
    adapter.set_attr("foo", 1)
    assert adapter.get_attr("foo") == [1, 1, 1]
    with pytest.raises(RuntimeError, match="without a pending step_async"):
        adapter.step_wait()
    with pytest.raises(ValueError, match="shape"):
        adapter.step(np.zeros((3, 2), dtype=np.float32))
    adapter.close()


@pytest.mark.skipif(HAVE_SB3, reason="stable-baselines3 is installed")
def test_sb3_wrapper_without_sb3_names_the_package():
    import ms2.wrappers

    with pytest.raises(ImportError, match="stable-baselines3"):
        _ = ms2.wrappers.SB3VecEnvWrapper


#: A stand-in for stable-baselines3's ``VecEnv`` base class (its constructor and abstract
#: methods), to test how SB3VecEnvWrapper is built where the real package is not installed.
FAKE_SB3_BASE = """
from abc import ABC, abstractmethod


class VecEnv(ABC):
    def __init__(self, num_envs, observation_space, action_space):
        self.num_envs = num_envs
        self.observation_space = observation_space
        self.action_space = action_space
        self.reset_infos = [{} for _ in range(num_envs)]
        self.render_mode = self.get_attr("render_mode")[0]

    def step(self, actions):
        self.step_async(actions)
        return self.step_wait()

    @abstractmethod
    def reset(self, *args, **kwargs): ...

    @abstractmethod
    def step_async(self, *args, **kwargs): ...

    @abstractmethod
    def step_wait(self, *args, **kwargs): ...

    @abstractmethod
    def close(self, *args, **kwargs): ...

    @abstractmethod
    def get_attr(self, *args, **kwargs): ...

    @abstractmethod
    def set_attr(self, *args, **kwargs): ...

    @abstractmethod
    def env_method(self, *args, **kwargs): ...

    @abstractmethod
    def env_is_wrapped(self, *args, **kwargs): ...
"""


@pytest.mark.skipif(HAVE_SB3, reason="stable-baselines3 is installed (tested for real below)")
def test_sb3_vec_env_wrapper_class_over_a_stand_in_base(tmp_path, monkeypatch):
    package = tmp_path / "stable_baselines3" / "common" / "vec_env"
    package.mkdir(parents=True)
    for folder in (package, package.parent, package.parent.parent):
        (folder / "__init__.py").write_text("")
    (package / "base_vec_env.py").write_text(FAKE_SB3_BASE)
    monkeypatch.syspath_prepend(str(tmp_path))
    from ms2.wrappers import sb3_vec_env

    sb3_vec_env._sb3_vec_env_class.cache_clear()
    try:
        from ms2.wrappers import SB3VecEnvWrapper
        from stable_baselines3.common.vec_env.base_vec_env import VecEnv

        venv = SB3VecEnvWrapper(ms2.make_vec(MAIN_ID, num_envs=2, max_episode_steps=2))
        assert isinstance(venv, VecEnv) and isinstance(venv, SB3VecEnvAdapter)
        assert SB3VecEnvWrapper.__module__ == "ms2.wrappers.sb3_vec_env"
        assert venv.render_mode is None and venv.num_envs == 2
        venv.reset()
        venv.step(np.zeros((2, *venv.action_space.shape)))
        _, _, dones, infos = venv.step(np.zeros((2, *venv.action_space.shape)))
        assert dones.all() and "terminal_observation" in infos[1]
        venv.close()
    finally:
        sb3_vec_env._sb3_vec_env_class.cache_clear()
        for name in [m for m in sys.modules if m.startswith("stable_baselines3")]:
            del sys.modules[name]


def test_sb3_vec_env_wrapper():
    pytest.importorskip("stable_baselines3")
    from ms2.wrappers import SB3VecEnvWrapper
    from stable_baselines3.common.vec_env import VecEnv

    venv = SB3VecEnvWrapper(ms2.make_vec(MAIN_ID, num_envs=2, max_episode_steps=3))
    assert isinstance(venv, VecEnv) and isinstance(venv, SB3VecEnvAdapter)
    obs = venv.reset()
    assert obs.shape == (2, *venv.observation_space.shape)
    for _ in range(3):
        obs, rewards, dones, infos = venv.step(np.zeros((2, *venv.action_space.shape)))
    assert dones.all() and "terminal_observation" in infos[0]
    venv.close()
