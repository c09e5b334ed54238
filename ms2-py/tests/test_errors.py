"""Bad input raises ordinary Python exceptions naming the bad value and the valid ones."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import ENV_IDS, MAIN_ID
from ms2 import _native


@pytest.fixture
def env():
    e = ms2.Ms2Env(MAIN_ID, obs_mode="state")
    e.reset(seed=0)
    return e


def _dim(env) -> int:
    return env.action_space.shape[0]


@pytest.mark.parametrize("change", ["short", "long", "2d", "scalar", "empty"])
def test_wrong_action_shape(env, change):
    d = _dim(env)
    shape = {"short": (d - 1,), "long": (d + 1,), "2d": (1, d), "scalar": (), "empty": (0,)}[change]
    with pytest.raises(ValueError, match=rf"\({d},\)"):
        env.step(np.zeros(shape, np.float32))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_action(env, bad):
    action = np.zeros(_dim(env), np.float32)
    action[1] = bad
    with pytest.raises(ValueError, match="index 1"):
        env.step(action)
    # The env is still usable afterwards.
    env.step(np.zeros(_dim(env), np.float32))


def test_action_dtypes_and_layouts_are_accepted(env):
    d = _dim(env)
    env.step([0.0] * d)
    env.step(np.zeros(d, np.float64))
    env.step(np.zeros(2 * d, np.float32)[::2])  # non-contiguous view
    with pytest.raises(ValueError):
        env.step(["a"] * d)


def test_real_array_takes_float32_as_is_and_casts_the_rest():
    from ms2.envs import real_array

    view = np.arange(12, dtype=np.float32).reshape(3, 4)[:, ::2]  # float32, not contiguous
    out = real_array(view, "a")
    assert out.dtype == np.float32 and out.flags.c_contiguous
    np.testing.assert_array_equal(out, view)
    # A cast beyond float32's range gives inf (refused by the native step), without a warning.
    assert real_array(np.array([1e39, 2.0]), "a").tolist() == [np.inf, 2.0]
    with pytest.raises(ValueError, match="real numbers"):
        real_array(np.array([1j]), "a")


def test_unknown_env_id_lists_valid_ones():
    with pytest.raises(ValueError, match=ENV_IDS[0]) as err:
        ms2.Ms2Env("NoSuchTask-v0")
    assert "NoSuchTask-v0" in str(err.value)
    with pytest.raises(ValueError, match=ENV_IDS[-1]):
        ms2.make_vec("NoSuchTask-v0", num_envs=2)


@pytest.mark.parametrize(
    ("kwarg", "bad", "valid"),
    [
        ("obs_mode", "stat", "state_dict"),
        ("control_mode", "pd_joint_delta_poss", "pd_joint_delta_pos"),
        ("reward_mode", "densest", "normalized_dense"),
    ],
)
def test_unknown_modes_list_valid_ones(kwarg, bad, valid):
    with pytest.raises(ValueError, match=valid) as err:
        gym.make(MAIN_ID, **{kwarg: bad})
    assert bad in str(err.value)
    with pytest.raises(ValueError, match=valid):
        ms2.make_vec(MAIN_ID, num_envs=2, **{kwarg: bad})


def test_bad_seeds_and_sizes(env):
    with pytest.raises(ValueError, match="seed"):
        env.reset(seed=-1)
    with pytest.raises(ValueError, match="num_envs"):
        ms2.make_vec(MAIN_ID, num_envs=0)


def test_rust_panic_becomes_runtime_error():
    with pytest.raises(RuntimeError, match="Rust panic.*deliberate"):
        _native._panic_for_tests("deliberate")
    # A RuntimeError is an Exception (pyo3's own PanicException is not).
    with pytest.raises(Exception, match="again"):  # noqa: PT011
        _native._panic_for_tests("again")
