"""Soft-body trajectories (Fill-v0) in ManiSkill2's soft layout: ``env_init_state`` instead of
per-step ``env_states``; recording, generating, replaying, converting, videos and foreign files."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import h5py
import numpy as np
import pytest
from ms2.cli import main
from ms2.demos import replay
from ms2.recording import RecordEpisode
from ms2.trajectory import TrajectoryFileError, open_trajectory

STEPS = 4


def _recorded_soft_episode(tmp_path: Path) -> tuple[Path, np.ndarray, np.ndarray, list[bool]]:
    """Records STEPS steps of Fill-v0 (particles obs) with RecordEpisode; returns the file, the
    env's final state and final particle positions, and the success flags."""
    env = RecordEpisode(
        gym.make("Fill-v0", obs_mode="particles"),
        tmp_path,
        save_video=False,
        trajectory_name="fill",
    )
    env.reset(seed=5)
    rng = np.random.default_rng(0)
    success = []
    for _ in range(STEPS):
        action = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, _r, _term, _trunc, info = env.step(action)
        success.append(bool(info["success"]))
    final_state = env.unwrapped.get_state()
    env.close()
    return tmp_path / "fill.h5", final_state, obs["particles"]["x"], success


def test_recorded_soft_episode_keeps_init_state_and_replays_bit_for_bit(tmp_path):
    path, final_state, final_x, success = _recorded_soft_episode(tmp_path)
    with h5py.File(path, "r") as f:
        # ManiSkill2's RecordEpisode layout: the observations (obs) and, soft-body, the
        # initial state only.
        assert set(f["traj_0"].keys()) == {"actions", "success", "env_init_state", "obs"}
        init = f["traj_0/env_init_state"]
        assert init.dtype == np.float32 and init.shape == final_state.shape
    meta = json.loads(path.with_suffix(".json").read_text())
    assert meta["env_info"]["env_kwargs"]["mpm_freq"] == 2000.0
    with open_trajectory(path) as traj:
        assert traj.is_soft(0)
        (episode,) = list(traj)
    assert "env_states" not in episode
    np.testing.assert_array_equal(episode["success"], success)

    # ms2 replay re-simulates from env_init_state: same success and final particles, bitwise.
    result = replay(path, obs_mode="particles", save_traj=True, allow_failure=True, progress=False)
    assert result.num_episodes == 1
    with open_trajectory(result.output) as out:
        replayed = out.read_episode(0, with_obs=True)
        assert out.env_info["env_kwargs"]["mpm_freq"] == 2000.0
    np.testing.assert_array_equal(replayed["env_init_state"], episode["env_init_state"])
    np.testing.assert_array_equal(replayed["success"], success)
    np.testing.assert_array_equal(replayed["obs"]["particles"]["x"][-1], final_x)
    # The whole state too, through a gym env restoring env_init_state and stepping the actions.
    env = gym.make("Fill-v0", obs_mode="state")
    env.reset(seed=episode["episode_seed"])
    env.unwrapped.set_state(episode["env_init_state"])
    for action in episode["actions"]:
        env.step(action)
    np.testing.assert_array_equal(env.unwrapped.get_state(), final_state)
    assert not np.array_equal(final_state, episode["env_init_state"])

    # --use-env-states has no per-step states to restore: refused by name.
    assert main(["replay", "--traj-path", str(path), "--use-env-states", "-q"]) == 2
    with pytest.raises(ValueError, match="--use-env-states.*env_init_state"):
        replay(path, use_env_states=True, progress=False)


def test_generated_soft_demos_replay_convert_and_render(tmp_path, capsys):
    path = tmp_path / "fill.h5"
    argv = [
        "demos",
        "generate",
        "Fill-v0",
        "--policy",
        "scripted",
        "-n",
        "2",
        "--output",
        str(path),
    ]
    assert main([*argv, "--workers", "2", "-q"]) == 0
    with open_trajectory(path) as traj:
        assert traj.env_info["env_kwargs"]["mpm_freq"] == 2000.0
        # Soft-body demos default to the soft envs' rate-limited pd_joint_delta_pos.
        assert traj.env_info["env_kwargs"]["control_mode"] == "pd_joint_delta_pos"
        assert all(traj.is_soft(i) for i in range(len(traj)))
    capsys.readouterr()
    assert main(["replay", "--traj-path", str(path), "--num-workers", "2", "-q"]) == 0
    assert "2 succeeded (100.0 %)" in capsys.readouterr().out

    # Closed-loop conversion re-simulates the source (a delta mode needs its joint positions at
    # every step) and succeeds; the copy is in the soft layout too.
    converted = replay(
        path,
        target_control_mode="pd_ee_delta_pose",
        save_traj=True,
        allow_failure=True,
        progress=False,
    )
    # Most Fill demos convert (docs/trajectory_format.md has the rate); seed-dependent ones
    # spill, so one of the two is enough here.
    assert converted.num_episodes == 2 and converted.num_succeeded >= 1
    with open_trajectory(converted.output) as out:
        assert out.env_info["env_kwargs"]["control_mode"] == "pd_ee_delta_pose"
        assert all(out.is_soft(i) for i in range(len(out)))
        episode = out.read_episode(0)
    with open_trajectory(path) as src:
        source = src.read_episode(0)
    assert episode["actions"].shape[0] >= source["actions"].shape[0]
    np.testing.assert_array_equal(episode["env_init_state"], source["env_init_state"])

    video = replay(path, save_video=True, count=1, progress=False).videos
    assert len(video) == 1 and video[0].stat().st_size > 1000


def test_maniskill2_soft_files_open_and_wrong_state_lengths_are_named(tmp_path):
    path = tmp_path / "ms2_excavate.h5"
    with h5py.File(path, "w") as f:
        f.create_dataset("traj_0/actions", data=np.zeros((3, 7), np.float32))
        f.create_dataset("traj_0/success", data=np.zeros(3, bool))
        f.create_dataset("traj_0/env_init_state", data=np.zeros(1234, np.float32))
    meta = {  # ManiSkill2 0.5's JSON: episodes without reset_kwargs
        "env_info": {
            "env_id": "Excavate-v0",
            "max_episode_steps": 250,
            "env_kwargs": {"obs_mode": "none", "control_mode": "pd_joint_delta_pos"},
        },
        "episodes": [
            {
                "episode_id": 0,
                "episode_seed": 7,
                "control_mode": "pd_joint_delta_pos",
                "elapsed_steps": 3,
                "info": {"success": False},
            }
        ],
    }
    path.with_suffix(".json").write_text(json.dumps(meta))
    with open_trajectory(path) as traj:
        episode = traj.read_episode(0)
    assert episode["env_init_state"].shape == (1234,)
    assert episode["reset_kwargs"] == {"seed": 7}
    with pytest.raises(TrajectoryFileError, match=r"ms2_excavate.h5: traj_0: env_init_state") as e:
        replay(path, progress=False)
    assert "ManiSkill2" in str(e.value)
