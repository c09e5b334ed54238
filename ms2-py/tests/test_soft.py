"""The soft-body envs (Excavate-v0, Fill-v0) from Python: particles, mpm_freq, states, records."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from ms2.recording import RecordEpisode
from ms2.trajectory import open_trajectory

SOFT_IDS = ("Excavate-v0", "Fill-v0")


@pytest.mark.parametrize("env_id", SOFT_IDS)
def test_particles_obs_mode_and_default_mpm_freq(env_id):
    env = gym.make(env_id, obs_mode="particles")
    assert env.unwrapped.mpm_freq == 2000.0  # ManiSkill2's rate
    space = env.observation_space["particles"]["x"]
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        assert obs["particles"]["x"].shape == space.shape, seed
    x = obs["particles"]["x"]
    assert x.dtype == np.float32 and x.ndim == 2 and x.shape[1] == 3 and x.shape[0] > 100
    assert np.isfinite(x).all()
    obs, _r, _term, _trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
    assert obs["particles"]["x"].shape == x.shape
    assert "success" in info
    env.close()


def test_mpm_freq_is_taken_and_recorded(tmp_path):
    env = RecordEpisode(
        gym.make("Excavate-v0", obs_mode="state", mpm_freq=2000),
        tmp_path,
        save_video=False,
        trajectory_name="excavate",
    )
    assert env.unwrapped.mpm_freq == 2000.0
    env.reset(seed=1)
    zero = np.zeros(env.action_space.shape, np.float32)
    for _ in range(2):
        env.step(zero)
    recorded_final = env.unwrapped.get_state()  # soft-body files keep env_init_state only
    env.close()
    with open_trajectory(tmp_path / "excavate.h5") as traj:
        assert traj.env_info["env_kwargs"]["mpm_freq"] == 2000.0
        (episode,) = list(traj)
    # The replay at the recorded frequency reproduces the states; at 1 kHz it does not.
    for mpm_freq, same in ((2000, True), (1000, False)):
        replay = gym.make("Excavate-v0", obs_mode="state", mpm_freq=mpm_freq)
        replay.reset(seed=episode["episode_seed"])
        for action in episode["actions"]:
            replay.step(action)
        final = replay.unwrapped.get_state()
        assert np.array_equal(final, recorded_final) == same, mpm_freq


@pytest.mark.parametrize(
    ("env_id", "kwargs", "error", "named"),
    [
        ("Excavate-v0", {"mpm_freq": 1234}, ValueError, "1234"),
        ("Excavate-v0", {"mpm_freq": float("nan")}, ValueError, "NaN"),
        ("Fill-v0", {"mpm_freq": 0}, ValueError, "mpm_freq"),
        ("Excavate-v0", {"mpm_freq": 1000, "sim_freq": 300, "control_freq": 20}, ValueError, "300"),
        ("PickCube-v0", {"mpm_freq": 2000}, ValueError, "PickCube-v0"),
        ("Excavate-v0", {"mpm_freq": "fast"}, TypeError, "fast"),
    ],
)
def test_bad_mpm_freq_is_refused_by_name(env_id, kwargs, error, named):
    with pytest.raises(error, match="mpm_freq") as err:
        gym.make(env_id, **kwargs)
    assert named in str(err.value)
    with pytest.raises(error, match="mpm_freq"):
        ms2.make_vec(env_id, num_envs=2, **kwargs)


def test_state_round_trip_repeats_the_continuation():
    env = gym.make("Fill-v0", obs_mode="particles")
    env.reset(seed=4)
    zero = np.zeros(env.action_space.shape, np.float32)
    env.step(zero)
    saved = env.unwrapped.get_state()
    later = [env.step(zero)[0]["particles"]["x"] for _ in range(2)]
    env.unwrapped.set_state(saved)
    again = [env.step(zero)[0]["particles"]["x"] for _ in range(2)]
    for a, b in zip(later, again, strict=True):
        np.testing.assert_array_equal(a, b)
