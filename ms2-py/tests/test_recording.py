"""RecordEpisode's trajectory files and ``ms2 run --record``."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest
from ms2.cli import main
from ms2.recording import RecordEpisode
from ms2.trajectory import open_trajectory


def _run_scripted(env, seed: int, max_steps: int) -> int:
    """Runs the scripted policy for one episode (at most ``max_steps``); returns its steps."""
    policy = ms2.ScriptedPolicy(env)
    env.reset(seed=seed)
    policy.reset()
    for _ in range(max_steps):
        _obs, _reward, terminated, truncated, _info = env.step(policy.act())
        if terminated or truncated:
            break
    return env.unwrapped.elapsed_steps


def test_recorded_trajectory_replays_to_the_same_states(tmp_path):
    env = RecordEpisode(
        gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose"),
        tmp_path,
        save_video=False,
        trajectory_name="pick",
    )
    steps = [_run_scripted(env, seed, max_steps) for seed, max_steps in ((3, 25), (8, 15))]
    env.reset(seed=99)  # ends episode 2; an episode without steps is not written
    env.close()

    with open_trajectory(tmp_path / "pick.h5") as traj:
        assert traj.env_id == "PickCube-v0"
        assert traj.env_info["max_episode_steps"] == 200
        assert traj.env_info["env_kwargs"]["control_mode"] == "pd_ee_delta_pose"
        assert [e["episode_seed"] for e in traj.episodes] == [3, 8]
        episodes = list(traj)

    replay = gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    for episode, expected_steps in zip(episodes, steps, strict=True):
        assert episode["control_mode"] == "pd_ee_delta_pose"
        assert episode["elapsed_steps"] == expected_steps
        assert episode["actions"].shape == (expected_steps, 7)
        assert episode["env_states"].shape[0] == expected_steps + 1
        replay.reset(seed=episode["episode_seed"])
        np.testing.assert_array_equal(replay.unwrapped.get_state(), episode["env_states"][0])
        for t, action in enumerate(episode["actions"]):
            _obs, _r, _term, _trunc, info = replay.step(action)
            np.testing.assert_array_equal(
                replay.unwrapped.get_state(), episode["env_states"][t + 1]
            )
            assert bool(info["success"]) == bool(episode["success"][t])


def test_unseeded_episodes_record_the_seed_that_replays_them(tmp_path):
    env = RecordEpisode(gym.make("LiftCube-v0"), tmp_path, save_video=False)
    env.reset()  # the env draws the episode seed
    drawn = env.unwrapped.episode_seed
    env.step(env.action_space.sample())
    env.close()
    with open_trajectory(tmp_path / "trajectory.h5") as traj:
        episode = traj.read_episode(0)
    assert episode["episode_seed"] == drawn
    fresh = gym.make("LiftCube-v0")
    fresh.reset(seed=drawn)
    np.testing.assert_array_equal(fresh.unwrapped.get_state(), episode["env_states"][0])


@pytest.mark.parametrize("name", ["", "a/b"])
def test_bad_trajectory_name_raises(name):
    with pytest.raises(ValueError, match="trajectory_name"):
        RecordEpisode(gym.make("PickCube-v0"), "unused", save_video=False, trajectory_name=name)


def test_run_record_saves_video_and_trajectory(tmp_path, capsys):
    pytest.importorskip("imageio_ffmpeg")
    out_dir = tmp_path / "rec"
    assert main(["run", "PickCube-v0", "--episodes", "1", "--record", str(out_dir)]) == 0
    printed = capsys.readouterr().out
    assert "trajectory:" in printed
    assert (out_dir / "episode_0.mp4").stat().st_size > 0
    with open_trajectory(out_dir / "PickCube-v0.h5") as traj:
        assert len(traj) == 1
        episode = traj.read_episode(0)
    assert episode["episode_seed"] == 0
    assert episode["success"][-1], "the scripted PickCube episode succeeds"
