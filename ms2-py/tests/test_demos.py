"""Demonstrations: trajectory files (layout, dtypes, atomic writes, errors), ``ms2 demos
generate`` and ``ms2 replay`` (replay with recorded states, closed-loop conversion)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from ms2 import _native
from ms2.cli import main
from ms2.demos import generate, replay, replay_output_path
from ms2.trajectory import TrajectoryFileError, TrajectoryWriter, open_trajectory

ENV_ID = "PickCube-v0"
NUM_DEMOS = 4


@pytest.fixture(scope="module")
def demo_file(tmp_path_factory) -> Path:
    """Four successful scripted PickCube demonstrations written by ``ms2 demos generate``."""
    path = tmp_path_factory.mktemp("demos") / "PickCube-v0.h5"
    argv = ["demos", "generate", ENV_ID, "-n", str(NUM_DEMOS), "--output", str(path)]
    assert main([*argv, "--workers", "2", "--policy", "scripted", "-q"]) == 0
    return path


def test_generated_files_have_maniskill2_layout_and_dtypes(demo_file):
    meta = json.loads(demo_file.with_suffix(".json").read_text())
    assert set(meta) == {"env_info", "episodes"}
    assert set(meta["env_info"]) == {"env_id", "max_episode_steps", "env_kwargs"}
    assert meta["env_info"]["env_id"] == ENV_ID
    assert meta["env_info"]["max_episode_steps"] == 200
    assert meta["env_info"]["env_kwargs"]["control_mode"] == "pd_joint_pos"
    episodes = meta["episodes"]
    assert [ep["episode_id"] for ep in episodes] == list(range(NUM_DEMOS))
    with h5py.File(demo_file, "r") as f:
        assert sorted(f.keys()) == [f"traj_{i}" for i in range(NUM_DEMOS)]
        state_len = None
        for ep in episodes:
            assert set(ep) == {
                "episode_id",
                "episode_seed",
                "reset_kwargs",
                "control_mode",
                "elapsed_steps",
                "info",
            }
            group = f[f"traj_{ep['episode_id']}"]
            assert set(group.keys()) == {"actions", "success", "env_states"}
            actions, success, states = group["actions"], group["success"], group["env_states"]
            steps = ep["elapsed_steps"]
            assert actions.dtype == np.float32 and actions.shape == (steps, 8)
            assert success.dtype == np.bool_ and success.shape == (steps,)
            assert states.dtype == np.float32 and states.shape[0] == steps + 1
            state_len = state_len or states.shape[1]
            assert states.shape[1] == state_len
            assert bool(success[-1]) and ep["info"]["success"] is True
            assert ep["control_mode"] == "pd_joint_pos"
            assert ep["reset_kwargs"] == {"seed": ep["episode_seed"]}
            assert ep["info"]["elapsed_steps"] == steps
    seeds = [ep["episode_seed"] for ep in episodes]
    assert seeds == sorted(set(seeds))


def test_writer_round_trips_episodes_and_nested_observations(tmp_path):
    rng = np.random.default_rng(0)
    path = tmp_path / "synthetic.h5"
    info = {"env_id": "X-v0", "max_episode_steps": 10, "env_kwargs": {"obs_mode": "state_dict"}}
    written = []
    with TrajectoryWriter(path, info) as writer:
        for seed, steps in [(5, 3), (9, 0)]:
            episode = {
                "episode_seed": seed,
                "control_mode": "pd_joint_pos",
                "actions": rng.normal(size=(steps, 8)).astype(np.float32),
                "success": np.arange(steps) == steps - 1,
                "env_states": rng.normal(size=(steps + 1, 12)).astype(np.float32),
                "elapsed_steps": steps,
                "info": {"success": np.bool_(steps > 0), "dist": np.float64(0.5)},
            }
            obs = {
                "agent": {"qpos": rng.normal(size=(steps + 1, 9)).astype(np.float32)},
                "image": rng.integers(0, 255, size=(steps + 1, 4, 4, 3), dtype=np.uint8),
            }
            writer.append(episode, obs=obs)
            written.append((episode, obs))
        writer.commit()
    with open_trajectory(path) as traj:
        assert len(traj) == 2 and traj.env_id == "X-v0"
        for i, (episode, obs) in enumerate(written):
            got = traj.read_episode(i, with_obs=True)
            for key in ("actions", "success", "env_states"):
                np.testing.assert_array_equal(got[key], episode[key])
                assert got[key].dtype == episode[key].dtype
            np.testing.assert_array_equal(got["obs"]["agent"]["qpos"], obs["agent"]["qpos"])
            assert got["obs"]["image"].dtype == np.uint8
            assert got["info"] == {"success": bool(episode["info"]["success"]), "dist": 0.5}
    with h5py.File(path, "r") as f:
        assert f["traj_0/obs/agent/qpos"].shape == (4, 9)


def test_bad_episode_arrays_are_refused(tmp_path):
    info = {"env_id": "X-v0", "max_episode_steps": 10, "env_kwargs": {}}
    episode = {
        "episode_seed": 1,
        "control_mode": "pd_joint_pos",
        "actions": np.zeros((3, 8), np.float64),
        "success": np.zeros(3, bool),
        "env_states": np.zeros((4, 5), np.float32),
    }
    with TrajectoryWriter(tmp_path / "bad.h5", info) as writer:
        with pytest.raises(ValueError, match="actions must be float32"):
            writer.append(episode)
        episode["actions"] = episode["actions"].astype(np.float32)
        episode["env_states"] = np.zeros((3, 5), np.float32)
        with pytest.raises(ValueError, match=r"env_states must be float32 \[4, S\]"):
            writer.append(episode)


def test_replay_with_env_states_reproduces_recorded_states_exactly(demo_file):
    result = replay(
        demo_file,
        obs_mode="state",
        use_env_states=True,
        save_traj=True,
        num_workers=2,
        progress=False,
    )
    assert result.num_succeeded == result.num_episodes == NUM_DEMOS
    out = replay_output_path(demo_file, "state", "pd_joint_pos")
    assert result.output == out and out.name == "PickCube-v0.state.pd_joint_pos.h5"
    with open_trajectory(demo_file) as src, open_trajectory(out) as dst:
        assert dst.env_info["env_kwargs"]["obs_mode"] == "state"
        for i in range(NUM_DEMOS):
            a, b = src.read_episode(i), dst.read_episode(i, with_obs=True)
            np.testing.assert_array_equal(b["env_states"], a["env_states"])
            np.testing.assert_array_equal(b["actions"], a["actions"])
            assert b["episode_seed"] == a["episode_seed"]
            assert b["obs"].dtype == np.float32
            assert b["obs"].shape[0] == a["env_states"].shape[0]


@pytest.mark.parametrize("target", ["pd_ee_delta_pose", "pd_joint_delta_pos"])
def test_converted_trajectories_succeed(demo_file, target, capsys):
    argv = ["replay", "--traj-path", str(demo_file), "-c", target, "--save-traj"]
    assert main([*argv, "--num-workers", "2", "-q"]) == 0
    assert f"{NUM_DEMOS} succeeded (100.0 %)" in capsys.readouterr().out
    out = replay_output_path(demo_file, None, target)
    assert out.name == f"PickCube-v0.none.{target}.h5"
    width = 7 if target == "pd_ee_delta_pose" else 8
    with open_trajectory(out) as traj:
        assert len(traj) == NUM_DEMOS
        assert traj.env_info["env_kwargs"]["control_mode"] == target
        for i in range(NUM_DEMOS):
            ep = traj.read_episode(i)
            assert ep["control_mode"] == target
            assert ep["actions"].shape[1] == width
            assert ep["success"][-1] and ep["info"]["success"]
            assert np.all(np.abs(ep["actions"]) <= 1.0 + 1e-6)  # normalised target space
    if target == "pd_joint_delta_pos":
        # ... and back: pd_joint_delta_pos -> pd_joint_pos.
        back = replay(out, target_control_mode="pd_joint_pos", save_traj=True, progress=False)
        assert back.num_succeeded == NUM_DEMOS
        assert back.output.name == f"PickCube-v0.none.{target}.none.pd_joint_pos.h5"


def test_track_hand_only_converts_by_the_hand_path_alone(demo_file, capsys):
    # The default conversion moves the hand so the held cube follows the source's cube; with
    # --track-hand-only (ManiSkill2's converter) the hand follows the source's hand: both
    # succeed on PickCube, with different actions while the cube is held.
    corrected = replay(demo_file, target_control_mode="pd_ee_delta_pose", count=2, progress=False)
    assert corrected.num_succeeded == 2
    argv = ["replay", "--traj-path", str(demo_file), "-c", "pd_ee_delta_pose", "--save-traj"]
    assert main([*argv, "--count", "2", "--track-hand-only", "-q"]) == 0
    assert "2 succeeded (100.0 %)" in capsys.readouterr().out
    hand_only = replay_output_path(demo_file, None, "pd_ee_delta_pose")
    with open_trajectory(hand_only) as traj:
        hand_actions = [traj.read_episode(i)["actions"] for i in range(2)]
    replay(
        demo_file, target_control_mode="pd_ee_delta_pose", count=2, save_traj=True, progress=False
    )
    with open_trajectory(hand_only) as traj:
        held_actions = [traj.read_episode(i)["actions"] for i in range(2)]
    assert any(
        a.shape != b.shape or not np.array_equal(a, b)
        for a, b in zip(hand_actions, held_actions, strict=True)
    )


def test_replayed_state_dict_observations_are_nested_groups(demo_file):
    replay(demo_file, obs_mode="state_dict", save_traj=True, count=1, progress=False)
    out = replay_output_path(demo_file, "state_dict", "pd_joint_pos")
    with h5py.File(out, "r") as f:
        steps = f["traj_0/actions"].shape[0]
        assert f["traj_0/obs/agent/qpos"].shape == (steps + 1, 9)
        assert f["traj_0/obs/agent/qpos"].dtype == np.float32
        assert "extra" in f["traj_0/obs"]


def test_missing_truncated_and_foreign_files_give_clear_errors(demo_file, tmp_path, capsys):
    missing = tmp_path / "nothing.h5"
    with pytest.raises(FileNotFoundError, match="nothing.h5"):
        open_trajectory(missing)
    assert main(["replay", "--traj-path", str(missing)]) == 2
    assert "nothing.h5: trajectory file not found" in capsys.readouterr().err

    no_json = tmp_path / "no_json.h5"
    no_json.write_bytes(demo_file.read_bytes())
    with pytest.raises(FileNotFoundError, match=r"no_json.json: metadata file"):
        open_trajectory(no_json)

    data = demo_file.read_bytes()
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(data[: len(data) // 2])
    truncated.with_suffix(".json").write_text(demo_file.with_suffix(".json").read_text())
    with pytest.raises(TrajectoryFileError, match=r"truncated.h5: not a readable HDF5"):
        open_trajectory(truncated)

    text = tmp_path / "text.h5"
    text.write_text("hello")
    text.with_suffix(".json").write_text(demo_file.with_suffix(".json").read_text())
    with pytest.raises(ValueError, match=r"text.h5: not a readable HDF5"):
        open_trajectory(text)

    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f.create_dataset("images", data=np.zeros(3))
    foreign.with_suffix(".json").write_text(demo_file.with_suffix(".json").read_text())
    with pytest.raises(TrajectoryFileError, match=r"foreign.h5: not a trajectory file"):
        open_trajectory(foreign)

    short_json = tmp_path / "short_json.h5"
    short_json.write_bytes(data)
    text_json = demo_file.with_suffix(".json").read_text()
    short_json.with_suffix(".json").write_text(text_json[: len(text_json) // 2])
    with pytest.raises(TrajectoryFileError, match=r"short_json.json: not valid JSON"):
        open_trajectory(short_json)

    other_json = tmp_path / "other_json.h5"
    other_json.write_bytes(data)
    other_json.with_suffix(".json").write_text(json.dumps({"config": 1}))
    with pytest.raises(TrajectoryFileError, match="not a trajectory metadata file"):
        open_trajectory(other_json)

    soft = tmp_path / "soft.h5"
    with h5py.File(soft, "w") as f:
        f.create_dataset("traj_0/actions", data=np.zeros((2, 8), np.float32))
        f.create_dataset("traj_0/success", data=np.zeros(2, bool))
        f.create_dataset("traj_0/env_init_state", data=np.zeros(5, np.float32))
    soft_meta = json.loads(text_json)
    soft_meta["episodes"] = soft_meta["episodes"][:1]
    soft_meta["episodes"][0]["elapsed_steps"] = 2
    soft.with_suffix(".json").write_text(json.dumps(soft_meta))
    # The soft-body layout opens; a state of another length than the env's cannot replay.
    with open_trajectory(soft) as traj:
        episode = traj.read_episode(0)
    assert "env_states" not in episode and episode["env_init_state"].shape == (5,)
    with pytest.raises(TrajectoryFileError, match=r"soft.h5: traj_0: env_init_state has shape"):
        replay(soft, progress=False)
    with h5py.File(soft, "a") as f:
        del f["traj_0/env_init_state"]
        f.create_dataset("traj_0/env_init_state", data=np.zeros((2, 5), np.float32))
    with open_trajectory(soft) as traj, pytest.raises(TrajectoryFileError, match="soft.h5: traj_0"):
        traj.read_episode(0)

    fewer = tmp_path / "fewer.h5"
    with h5py.File(demo_file, "r") as src, h5py.File(fewer, "w") as dst:
        src.copy("traj_0", dst)
    fewer.with_suffix(".json").write_text(text_json)
    with pytest.raises(TrajectoryFileError, match=r"fewer.h5: 3 episode\(s\) .* missing"):
        open_trajectory(fewer)


def test_interrupted_writer_keeps_the_last_commit(tmp_path):
    path = tmp_path / "partial.h5"
    path.write_bytes(b"an older file of the same name")
    info = {"env_id": ENV_ID, "max_episode_steps": 200, "env_kwargs": {}}
    episodes = _native.scripted_episodes(ENV_ID, [0, 1, 2], {}, 2)
    with pytest.raises(KeyboardInterrupt):
        with TrajectoryWriter(path, info) as writer:
            writer.append(episodes[0])
            writer.commit()
            writer.append(episodes[1])
            writer.append(episodes[2])
            raise KeyboardInterrupt  # before the second commit
    with open_trajectory(path) as traj:
        assert len(traj) == 1
        np.testing.assert_array_equal(traj.read_episode(0)["actions"], episodes[0]["actions"])
    assert {p.name for p in tmp_path.iterdir()} == {"partial.h5", "partial.json"}


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
def test_interrupted_generate_leaves_a_valid_file_of_finished_episodes(tmp_path, sig):
    path = tmp_path / "killed.h5"
    cmd = [sys.executable, "-m", "ms2", "demos", "generate", ENV_ID, "-n", "400", "--output",
           str(path), "--workers", "1", "--policy", "scripted", "-q"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            json_file = path.with_suffix(".json")
            if json_file.exists() and len(json.loads(json_file.read_text())["episodes"]) >= 4:
                break
            assert proc.poll() is None, proc.stderr.read().decode()
            time.sleep(0.05)
        os.kill(proc.pid, sig)
        proc.wait(timeout=60)
    finally:
        proc.kill()
        proc.wait()
    # Interrupted mid-run, not finished: SIGKILL kills it, Ctrl-C (SIGINT) ends it with 130.
    assert proc.returncode == (-signal.SIGKILL if sig == signal.SIGKILL else 130)
    if sig == signal.SIGINT:
        assert "interrupted" in proc.stderr.read().decode()
    with open_trajectory(path) as traj:
        assert 4 <= len(traj) < 400
        for i in range(len(traj)):
            ep = traj.read_episode(i)
            assert ep["success"][-1]
            assert ep["env_states"].shape[0] == ep["actions"].shape[0] + 1


def test_a_recorded_interrupt_stops_generate_at_the_next_chunk(tmp_path):
    """A SIGINT that something swallowed (Python drops exceptions raised in finalizers) is
    still on record: the run stops between chunks with the finished ones committed."""
    from ms2 import interrupts

    path = tmp_path / "recorded.h5"
    interrupts._requested.set()
    try:
        with pytest.raises(KeyboardInterrupt):
            generate(ENV_ID, 50, path, policy="scripted", chunk_size=2, progress=False)
    finally:
        interrupts.clear()
    with open_trajectory(path) as traj:
        assert len(traj) == 0  # stopped before the first chunk, the empty file is valid
    assert generate(ENV_ID, 1, path, policy="scripted", progress=False).num_episodes == 1


def test_generate_with_the_motion_planning_solution(tmp_path):
    path = tmp_path / "solution.h5"
    if ENV_ID in _native.solution_env_ids():
        result = generate(ENV_ID, 2, path, num_workers=2, progress=False)
        assert result.num_episodes == 2
        with open_trajectory(path) as traj:
            assert all(traj.read_episode(i)["success"][-1] for i in range(2))
    else:
        with pytest.raises(ValueError, match="policy='scripted'"):
            generate(ENV_ID, 2, path, progress=False)


def test_bad_arguments_are_refused(demo_file, tmp_path):
    with pytest.raises(ValueError, match=r"num_episodes must be in \[1, 10000000\], got 0"):
        generate(ENV_ID, 0, tmp_path / "x.h5", policy="scripted")
    with pytest.raises(ValueError, match="unknown policy"):
        generate(ENV_ID, 1, tmp_path / "x.h5", policy="teleop")
    with pytest.raises(ValueError, match="use_env_states"):
        replay(
            demo_file, target_control_mode="pd_ee_delta_pose", use_env_states=True, progress=False
        )
    with pytest.raises(ValueError, match="pd_teleport"):
        replay(demo_file, target_control_mode="pd_teleport", progress=False)
    with pytest.raises(TypeError, match='unexpected keyword argument "colour"'):
        _native.replay_episodes(ENV_ID, [], {"colour": "red"})


def test_replay_saves_one_video_per_episode(demo_file):
    result = replay(demo_file, save_video=True, count=1, progress=False)
    assert [v.name for v in result.videos] == ["traj_0.mp4"]
    assert result.videos[0].parent.name == "PickCube-v0.none.pd_joint_pos.videos"
    assert result.videos[0].stat().st_size > 1000


def test_a_new_writer_replaces_an_older_file_from_its_first_commit(demo_file, tmp_path):
    path = tmp_path / "again.h5"
    path.write_bytes(demo_file.read_bytes())
    path.with_suffix(".json").write_text(demo_file.with_suffix(".json").read_text())
    info = {"env_id": ENV_ID, "max_episode_steps": 200, "env_kwargs": {}}
    with TrajectoryWriter(path, info) as writer:
        writer.commit()
    with open_trajectory(path) as traj:
        assert len(traj) == 0
        assert list(traj.h5.keys()) == []
