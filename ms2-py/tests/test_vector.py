"""``ms2.make_vec``: batched native stepping that matches N single envs, gymnasium autoreset."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from conftest import MAIN_ID, assert_obs_equal, preferred_control_mode, random_actions


def _single_envs(n, **kwargs):
    return [ms2.Ms2Env(MAIN_ID, **kwargs) for _ in range(n)]


@pytest.mark.parametrize("obs_mode", ["state", "state_dict"])
def test_vector_matches_single_envs_with_autoreset(obs_mode):
    n, limit = 3, 6
    kwargs = dict(
        obs_mode=obs_mode, control_mode=preferred_control_mode(MAIN_ID), max_episode_steps=limit
    )
    envs = ms2.make_vec(MAIN_ID, num_envs=n, **kwargs)
    singles = _single_envs(n, **kwargs)
    assert envs.single_observation_space == singles[0].observation_space
    assert envs.single_action_space == singles[0].action_space

    batch, infos = envs.reset(seed=100)
    expected = [s.reset(seed=100 + i)[0] for i, s in enumerate(singles)]
    assert batch in envs.observation_space
    for i in range(n):
        assert_obs_equal(_row(batch, i), expected[i])

    rng = np.random.default_rng(5)
    pending = [False] * n
    saw_autoreset = False
    for step in range(2 * limit + 2):
        actions = random_actions(envs.single_action_space, rng, n)
        batch, rewards, terminated, truncated, infos = envs.step(actions)
        assert rewards.dtype == np.float64 and rewards.shape == (n,)
        assert terminated.dtype == np.bool_ and truncated.dtype == np.bool_
        for i, env in enumerate(singles):
            if pending[i]:
                obs, _ = env.reset()
                reward, term, trunc = 0.0, False, False
                saw_autoreset = True
            else:
                obs, reward, term, trunc, info = env.step(actions[i])
                assert infos["_elapsed_steps"][i]
                assert infos["elapsed_steps"][i] == info["elapsed_steps"]
            assert_obs_equal(_row(batch, i), obs)
            assert rewards[i] == reward, (step, i)
            assert terminated[i] == term and truncated[i] == trunc, (step, i)
            pending[i] = term or trunc
    assert saw_autoreset


def _row(batch, i):
    if isinstance(batch, dict):
        return {k: _row(v, i) for k, v in batch.items()}
    return batch[i]


def test_vector_info_and_spaces():
    envs = ms2.make_vec(MAIN_ID, num_envs=4, obs_mode="state")
    single = ms2.Ms2Env(MAIN_ID, obs_mode="state").observation_space
    assert envs.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP
    assert envs.observation_space.shape == (4, *single.shape)
    obs, info = envs.reset(seed=0)
    assert obs.shape == (4, *single.shape) and obs.dtype == np.float32
    obs, rewards, term, trunc, info = envs.step(envs.action_space.sample())
    assert info["success"].dtype == np.bool_ and info["success"].shape == (4,)
    assert info["_success"].all()
    assert (info["elapsed_steps"] == 1).all()
    # Different seeds per env give different initial states.
    assert len({tuple(row) for row in envs.reset(seed=0)[0]}) == 4


def test_vector_seed_list_and_reset_mask():
    envs = ms2.make_vec(MAIN_ID, num_envs=3, obs_mode="state")
    a, _ = envs.reset(seed=[5, 6, 7])
    b, _ = envs.reset(seed=5)
    np.testing.assert_array_equal(a, b)
    zero = np.zeros(envs.action_space.shape, np.float32)
    stepped, *_ = envs.step(zero)
    mask = np.array([False, True, False])
    c, info = envs.reset(seed=[None, 6, None], options={"reset_mask": mask})
    np.testing.assert_array_equal(c[1], a[1])
    np.testing.assert_array_equal(c[[0, 2]], stepped[[0, 2]])
    assert info["_elapsed_steps"].tolist() == [False, True, False]
    with pytest.raises(ValueError, match="one seed per env"):
        envs.reset(seed=[1, 2])


def test_vector_bad_actions():
    envs = ms2.make_vec(MAIN_ID, num_envs=2, obs_mode="state")
    envs.reset(seed=0)
    d = envs.single_action_space.shape[0]
    with pytest.raises(ValueError, match="shape"):
        envs.step(np.zeros((3, d), np.float32))
    with pytest.raises(ValueError, match="shape"):
        envs.step(np.zeros((2, d + 1), np.float32))
    bad = np.zeros((2, d), np.float32)
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match="env 1"):
        envs.step(bad)
    # Nothing was stepped by the refused call: both envs are still at step 0.
    _, _, _, _, info = envs.step(np.zeros((2, d), np.float32))
    assert info["elapsed_steps"].tolist() == [1, 1]


def test_gymnasium_make_vec_uses_native_vector_env():
    envs = gym.make_vec(
        MAIN_ID, num_envs=2, vectorization_mode="vector_entry_point", obs_mode="state"
    )
    assert isinstance(envs.unwrapped, ms2.Ms2VectorEnv)
    obs, _ = envs.reset(seed=1)
    assert obs.shape == (2, *envs.single_observation_space.shape)


def test_vector_pool_variable(monkeypatch):
    """MS2_VEC_POOL chooses the native pool of rigid state steps; both step alike."""
    kwargs = dict(obs_mode="state", control_mode=preferred_control_mode(MAIN_ID))
    outputs = []
    for pool in ("spinning", "rayon"):
        monkeypatch.setenv("MS2_VEC_POOL", pool)
        envs = ms2.make_vec(MAIN_ID, num_envs=2, **kwargs)
        envs.reset(seed=3)
        outputs.append(envs.step(np.zeros(envs.action_space.shape, dtype=np.float32))[0])
        envs.close()
    np.testing.assert_array_equal(outputs[0], outputs[1])
    monkeypatch.setenv("MS2_VEC_POOL", "fast")
    with pytest.raises(ValueError, match="MS2_VEC_POOL.*'fast'"):
        ms2.make_vec(MAIN_ID, num_envs=2, **kwargs)
