"""ManiSkill2's file habits: ``RecordEpisode``'s options, replay naming and options, and the
trajectory files ManiSkill2 0.5.3 itself wrote (``fixtures/maniskill2``, README there)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import gymnasium as gym
import h5py
import numpy as np
import pytest
from ms2.demos import replay
from ms2.maniskill2_states import LAYOUTS, UnmappableStateError, map_states
from ms2.recording import RecordEpisode
from ms2.trajectory import open_trajectory

FIXTURES = Path(__file__).parent / "fixtures" / "maniskill2"
RIGID = "PickCube-v0"
SOFT = "Fill-v0"


def _run(env, steps, seed=0):
    env.action_space.seed(seed)
    env.reset(seed=seed)
    for _ in range(steps):
        env.step(env.action_space.sample())


def test_record_with_cameras_info_on_video_and_state_obs(tmp_path):
    env = gym.make(RIGID, render_mode="cameras", max_episode_steps=5)
    env = RecordEpisode(env, tmp_path, info_on_video=True)
    for episode in range(2):
        env.reset(seed=episode)
        for _ in range(7):  # past the limit: ManiSkill2 keeps recording until the next reset
            env.step(env.action_space.sample())
    env.close()
    assert sorted(p.name for p in tmp_path.glob("*.mp4")) == ["episode_0.mp4", "episode_1.mp4"]
    import imageio.v2 as imageio

    frames = imageio.mimread(tmp_path / "episode_0.mp4")
    assert len(frames) == 8 and frames[0].shape[:2] == (512, 640)
    with open_trajectory(tmp_path / "trajectory.h5") as traj:
        assert traj.env_info["env_kwargs"]["obs_mode"] == "state"
        episode = traj.read_episode(1, with_obs=True)
        assert episode["obs"].shape == (8, 51)
        assert episode["env_states"].shape[0] == 8


def test_info_on_video_writes_text_on_frames(tmp_path):
    frames = {}
    for flag in (False, True):
        env = RecordEpisode(
            gym.make(RIGID, render_mode="rgb_array"),
            tmp_path / str(flag),
            save_trajectory=False,
            info_on_video=flag,
        )
        _run(env, 2)
        frames[flag] = [f.copy() for f in env._frames]
        env.close()
    assert np.array_equal(frames[False][0], frames[True][0])  # reset frame: no info yet
    changed = np.any(frames[False][1] != frames[True][1], axis=-1)
    assert changed[:60, :200].mean() > 0.05 and changed[200:].mean() == 0


def test_save_on_reset_false_writes_only_on_flush(tmp_path):
    env = RecordEpisode(gym.make(RIGID, render_mode="rgb_array"), tmp_path, save_on_reset=False)
    _run(env, 3, seed=1)
    _run(env, 2, seed=2)  # replaces episode 0's data: never flushed
    assert not (tmp_path / "trajectory.h5").exists()
    env.flush_trajectory()
    video = env.flush_video(suffix="last")
    env.close()
    assert video == tmp_path / "episode_1_last.mp4" and video.exists()
    with open_trajectory(tmp_path / "trajectory.h5") as traj:
        assert [e["episode_seed"] for e in traj.episodes] == [2]
        assert traj.read_episode(0)["actions"].shape[0] == 2


def test_clean_on_close_false_keeps_episode_ids(tmp_path):
    env = RecordEpisode(
        gym.make(RIGID), tmp_path, save_video=False, save_on_reset=False, clean_on_close=False
    )
    for seed in range(3):
        _run(env, 2, seed=seed)
        if seed != 1:
            env.flush_trajectory()
    env.close()
    meta = json.loads((tmp_path / "trajectory.json").read_text())
    assert [e["episode_id"] for e in meta["episodes"]] == [0, 2]
    with h5py.File(tmp_path / "trajectory.h5") as f:
        assert sorted(f) == ["traj_0", "traj_2"]


def test_soft_env_records_init_state_and_obs(tmp_path):
    env = RecordEpisode(gym.make(SOFT, obs_mode="none"), tmp_path, save_video=False)
    _run(env, 2)
    env.close()
    with h5py.File(tmp_path / "trajectory.h5") as f:
        assert "env_init_state" in f["traj_0"] and "obs" in f["traj_0"]


def test_gym_make_from_a_recorded_files_env_kwargs(tmp_path):
    env = RecordEpisode(gym.make(RIGID, obs_mode="none"), tmp_path, save_video=False)
    _run(env, 2)
    env.close()
    info = json.loads((tmp_path / "trajectory.json").read_text())["env_info"]
    assert info["env_kwargs"]["obs_mode"] == "none"
    rebuilt = gym.make(info["env_id"], **info["env_kwargs"])
    assert rebuilt.reset(seed=0)[0] == {}


@pytest.fixture(scope="module")
def state_demo(tmp_path_factory):
    """Two PickCube episodes recorded in obs mode ``state`` (pd_joint_delta_pos)."""
    out = tmp_path_factory.mktemp("state_demo")
    env = RecordEpisode(gym.make(RIGID, obs_mode="state"), out, save_video=False)
    for seed in (4, 5):
        _run(env, 6, seed=seed)
    env.close()
    return out / "trajectory.h5"


def test_replay_names_and_observes_as_the_source_env_kwargs(state_demo):
    result = replay(state_demo, save_traj=True, progress=False, allow_failure=True)
    assert result.output == state_demo.with_name("trajectory.state.pd_joint_delta_pos.h5")
    with open_trajectory(result.output) as traj:
        assert traj.env_info["env_kwargs"]["obs_mode"] == "state"
        episode = traj.read_episode(0, with_obs=True)
        assert episode["obs"].shape == (7, 51)
    none = replay(state_demo, obs_mode="none", save_traj=True, progress=False, allow_failure=True)
    assert none.output.name == "trajectory.none.pd_joint_delta_pos.h5"


def test_use_first_env_state_starts_from_the_recorded_state(state_demo, tmp_path):
    # Re-label the episodes with other seeds: only the first recorded state gives their scene.
    copy = tmp_path / "relabelled.h5"
    shutil.copyfile(state_demo, copy)
    meta = json.loads(state_demo.with_suffix(".json").read_text())
    for ep in meta["episodes"]:
        ep["episode_seed"] += 100
        ep["reset_kwargs"] = {"seed": ep["episode_seed"]}
    copy.with_suffix(".json").write_text(json.dumps(meta))
    kwargs = {"save_traj": True, "progress": False, "allow_failure": True}
    first = replay(copy, use_first_env_state=True, **kwargs)
    with open_trajectory(first.output) as out, open_trajectory(state_demo) as src:
        for i in range(2):
            replayed, recorded = out.read_episode(i), src.read_episode(i)
            np.testing.assert_array_equal(replayed["env_states"][0], recorded["env_states"][0])
            np.testing.assert_allclose(
                replayed["env_states"][-1], recorded["env_states"][-1], atol=1e-3
            )
    from_seed = replay(copy, **kwargs)
    with open_trajectory(from_seed.output) as out, open_trajectory(state_demo) as src:
        assert not np.allclose(
            out.read_episode(0)["env_states"][0], src.read_episode(0)["env_states"][0]
        )


def test_discard_timeout_counts_episodes_at_the_limit_as_failed(tmp_path):
    import ms2

    env = RecordEpisode(ms2.Ms2Env("Dummy-v0", max_episode_steps=4), tmp_path, save_video=False)
    policy_env = env.unwrapped
    policy = ms2.ScriptedPolicy(env)
    for seed in range(6):
        env.reset(seed=seed)
        policy.reset()
        for _ in range(4):
            env.step(policy.act())
    env.close()
    path = tmp_path / "trajectory.h5"
    kept = replay(path, progress=False)
    discarded = replay(path, progress=False, discard_timeout=True)
    assert kept.num_succeeded > 0 and discarded.num_succeeded == 0
    assert policy_env is not None


@pytest.mark.parametrize(
    ("env_id", "episodes", "successes"),
    [("PickCube-v0", 6, 5), ("LiftCube-v0", 4, 4), ("StackCube-v0", 3, 0)],
)
def test_maniskill2_files_replay_with_their_recorded_success(tmp_path, env_id, episodes, successes):
    src = FIXTURES / env_id / "trajectory.h5"
    with open_trajectory(src) as traj:
        recorded = [bool(traj.read_episode(i)["success"][-1]) for i in range(len(traj))]
    assert len(recorded) == episodes and sum(recorded) == successes
    for use_env_states in (True, False):
        result = replay(src, use_env_states=use_env_states, progress=False)
        failed = sorted(result.failed_episode_ids)
        assert failed == [i for i, ok in enumerate(recorded) if not ok], use_env_states


def test_maniskill2_file_converts_to_pd_joint_pos(tmp_path):
    src = tmp_path / "trajectory.h5"
    for name in ("trajectory.h5", "trajectory.json"):
        shutil.copyfile(FIXTURES / "PickCube-v0" / name, tmp_path / name)
    result = replay(src, target_control_mode="pd_joint_pos", save_traj=True, progress=False)
    assert result.num_succeeded == 5, result.failed_episode_ids
    assert result.output.name == "trajectory.none.pd_joint_pos.h5"
    back = replay(result.output, use_env_states=True, progress=False)  # now ms2's own layout
    assert back.num_succeeded == 5


def test_maniskill2_state_mapping_and_unmappable_layouts():
    import ms2

    env = ms2.Ms2Env(RIGID)
    env.reset(seed=0)
    template = env.get_state()
    with h5py.File(FIXTURES / RIGID / "trajectory.h5") as f:
        foreign = f["traj_0"]["env_states"][()]
    assert foreign.shape[1] == LAYOUTS[RIGID].length == 73
    mapped = map_states(foreign, RIGID, template)
    assert mapped.shape == (foreign.shape[0], template.size)
    env.set_state(mapped[0])
    obs = env.get_obs()
    np.testing.assert_allclose(obs[:9], foreign[0, 52:61], atol=1e-6)  # qpos
    with pytest.raises(
        UnmappableStateError,
        match=r"x\.h5: env states of PickCube-v0 have 70 floats; "
        r"expected ms2's \d+ or ManiSkill2 0\.5\.3's 73",
    ):
        map_states(np.zeros((2, 70), np.float32), RIGID, template, source="x.h5")
    with pytest.raises(UnmappableStateError, match="Dummy-v0"):
        map_states(np.zeros(5, np.float32), "Dummy-v0", np.zeros(3, np.float32))


def test_flushing_by_hand_then_resetting_writes_the_episode_once(tmp_path):
    env = RecordEpisode(gym.make(RIGID, render_mode="rgb_array"), tmp_path)
    _run(env, 3)
    env.flush_trajectory()
    env.flush_video()
    _run(env, 2, seed=1)  # save_on_reset: episode 0 is already written as it is
    env.close()
    with open_trajectory(tmp_path / "trajectory.h5") as traj:
        assert [e["episode_seed"] for e in traj.episodes] == [0, 1]
    assert env.video_paths == [tmp_path / "episode_0.mp4", tmp_path / "episode_1.mp4"]
