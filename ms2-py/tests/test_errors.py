"""Bad input raises ordinary Python exceptions naming the bad value and the valid ones."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from ms2 import _native


@pytest.fixture
def env():
    e = ms2.Ms2Env("PickCube-v0", obs_mode="state", control_mode="pd_joint_delta_pos")
    e.reset(seed=0)
    return e


@pytest.mark.parametrize("shape", [(7,), (9,), (1, 8), (), (0,)])
def test_wrong_action_shape(env, shape):
    with pytest.raises(ValueError, match=r"\(8,\)"):
        env.step(np.zeros(shape, np.float32))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_action(env, bad):
    action = np.zeros(8, np.float32)
    action[3] = bad
    with pytest.raises(ValueError, match="index 3"):
        env.step(action)
    # The env is still usable afterwards.
    env.step(np.zeros(8, np.float32))


def test_action_dtypes_and_layouts_are_accepted(env):
    env.step([0.0] * 8)
    env.step(np.zeros(8, np.float64))
    env.step(np.zeros(16, np.float32)[::2])  # non-contiguous view


def test_unknown_env_id_lists_valid_ones():
    with pytest.raises(ValueError, match="PickCube-v0") as err:
        ms2.Ms2Env("PickCub-v0")
    assert "PickCub-v0" in str(err.value)
    with pytest.raises(ValueError, match="StackCube-v0"):
        ms2.make_vec("NoSuchEnv-v0", num_envs=2)


@pytest.mark.parametrize(
    ("kwarg", "bad", "valid"),
    [
        ("obs_mode", "stat", "state_dict"),
        ("control_mode", "pd_ee_delta_posee", "pd_ee_delta_pose"),
        ("reward_mode", "densest", "normalized_dense"),
    ],
)
def test_unknown_modes_list_valid_ones(kwarg, bad, valid):
    with pytest.raises(ValueError, match=valid) as err:
        gym.make("PickCube-v0", **{kwarg: bad})
    assert bad in str(err.value)
    with pytest.raises(ValueError, match=valid):
        ms2.make_vec("PickCube-v0", num_envs=2, **{kwarg: bad})


def test_negative_seed(env):
    with pytest.raises(ValueError, match="seed"):
        env.reset(seed=-1)


def test_rust_panic_becomes_runtime_error():
    with pytest.raises(RuntimeError, match="Rust panic.*deliberate"):
        _native._panic_for_tests("deliberate")
    # RuntimeError is an Exception (pyo3's PanicException is not).
    try:
        _native._panic_for_tests("again")
    except Exception as err:  # noqa: BLE001
        assert isinstance(err, RuntimeError)
