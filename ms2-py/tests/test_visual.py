"""Visual observation modes, human renders and MP4 recording from Python."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest

ROBOT_TASKS = [i for i in ("PickCube-v0", "LiftCube-v0", "StackCube-v0") if i in ms2.env_ids()]
VISUAL_MODES = ["rgbd", "pointcloud", "rgbd_robot_seg", "pointcloud_robot_seg"]
CAMERAS = ["base_camera", "hand_camera"]
N_POINTS = len(CAMERAS) * 128 * 128


def check_visual_obs(obs, obs_mode: str, batch: tuple[int, ...] = ()) -> None:
    """ManiSkill2's keys, shapes and dtypes of a visual observation (with a leading batch)."""
    assert set(obs["extra"]) <= {"tcp_pose", "goal_pos"} and "tcp_pose" in obs["extra"]
    assert obs["agent"]["qpos"].shape == (*batch, 9)
    seg = obs_mode.endswith("robot_seg")
    if obs_mode.startswith("rgbd"):
        assert list(obs["image"]) == CAMERAS and list(obs["camera_param"]) == CAMERAS
        for cam in CAMERAS:
            image = obs["image"][cam]
            assert image["rgb"].shape == (*batch, 128, 128, 3) and image["rgb"].dtype == np.uint8
            assert image["depth"].shape == (*batch, 128, 128, 1)
            assert image["depth"].dtype == np.float32
            assert ("robot_seg" in image) == seg
            if seg:
                assert image["robot_seg"].dtype == np.bool_
                assert image["robot_seg"].shape == (*batch, 128, 128, 1)
            param = obs["camera_param"][cam]
            assert param["extrinsic_cv"].shape == (*batch, 3, 4)
            assert param["cam2world_gl"].shape == (*batch, 4, 4)
            assert param["intrinsic_cv"].shape == (*batch, 3, 3)
    else:
        cloud = obs["pointcloud"]
        assert cloud["xyzw"].shape == (*batch, N_POINTS, 4) and cloud["xyzw"].dtype == np.float32
        assert cloud["rgb"].shape == (*batch, N_POINTS, 3) and cloud["rgb"].dtype == np.uint8
        assert cloud["Segmentation"].shape == (*batch, N_POINTS, 4)
        assert cloud["Segmentation"].dtype == np.uint32
        assert ("robot_seg" in cloud) == seg
        if seg:
            assert cloud["robot_seg"].shape == (*batch, N_POINTS, 1)
            assert cloud["robot_seg"].any() and not cloud["robot_seg"].all()
        valid = cloud["xyzw"][..., 3] == 1
        assert valid.any()
        assert np.all(cloud["xyzw"][~valid] == 0)


@pytest.mark.parametrize("env_id", ROBOT_TASKS)
@pytest.mark.parametrize("obs_mode", VISUAL_MODES)
def test_every_task_steps_in_every_visual_mode(env_id, obs_mode):
    env = gym.make(env_id, obs_mode=obs_mode)
    obs, _ = env.reset(seed=0)
    check_visual_obs(obs, obs_mode)
    assert obs in env.observation_space
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    check_visual_obs(obs, obs_mode)
    assert obs in env.observation_space
    env.close()


def test_vector_env_stacks_visual_obs():
    venv = gym.make_vec("PickCube-v0", num_envs=2, obs_mode="rgbd_robot_seg")
    obs, _ = venv.reset(seed=0)
    check_visual_obs(obs, "rgbd_robot_seg", batch=(2,))
    obs, *_ = venv.step(venv.action_space.sample())
    check_visual_obs(obs, "rgbd_robot_seg", batch=(2,))
    venv.close()


def test_render_rgb_array_is_a_512_view():
    env = gym.make("PickCube-v0", render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (512, 512, 3) and frame.dtype == np.uint8
    assert frame.std() > 10, "not a blank image"
    env.close()


def test_segmentation_ids_name_what_the_cameras_see():
    env = gym.make("PickCube-v0", obs_mode="pointcloud")
    ids = env.unwrapped.segmentation_ids()
    assert {"ground", "cube", "panda_hand"} <= ids.keys()
    assert len(set(ids.values())) == len(ids) and min(ids.values()) >= 1
    obs, _ = env.reset(seed=1)
    seen = set(np.unique(obs["pointcloud"]["Segmentation"][..., 1]).tolist())
    assert ids["cube"] in seen and any(ids[f"panda_link{k}"] in seen for k in range(8))
    assert seen - {0} <= set(ids.values()), "every id seen has a name"
    with pytest.raises(ValueError, match="render"):
        ms2.Ms2Env("Dummy-v0").segmentation_ids()


def test_state_only_env_rejects_visual_modes():
    with pytest.raises(ValueError, match="render"):
        ms2.Ms2Env("Dummy-v0", obs_mode="rgbd")


def test_record_episode_writes_a_readable_mp4(tmp_path):
    imageio = pytest.importorskip("imageio.v2")
    from ms2.recording import RecordEpisode

    env = RecordEpisode(gym.make("PickCube-v0", render_mode="rgb_array"), tmp_path, fps=20)
    env.reset(seed=0)
    for _ in range(5):
        env.step(env.action_space.sample())
    env.close()
    assert env.video_paths == [tmp_path / "episode_0.mp4"]
    frames = list(imageio.get_reader(env.video_paths[0]).iter_data())  # its len() is inf
    assert len(frames) == 6  # reset + 5 steps
    assert frames[0].shape == (512, 512, 3)
    assert not list(tmp_path.glob(".*tmp*")), "no temporary files left"


def test_record_episode_needs_rgb_array():
    from ms2.recording import RecordEpisode

    with pytest.raises(ValueError, match="rgb_array"):
        RecordEpisode(gym.make("PickCube-v0"), "unused")


def test_camera_cfgs_change_shapes_globally_and_per_camera():
    env = gym.make(
        "PickCube-v0",
        obs_mode="rgbd",
        camera_cfgs={"width": 32, "height": 24, "hand_camera": {"width": 16, "fov": 1.0}},
    )
    obs, _ = env.reset(seed=0)
    assert obs["image"]["base_camera"]["rgb"].shape == (24, 32, 3)
    assert obs["image"]["base_camera"]["depth"].shape == (24, 32, 1)
    assert obs["image"]["hand_camera"]["rgb"].shape == (24, 16, 3)
    # fx = (H/2) / tan(fov/2): the hand camera's fov came from its own entry.
    fy = obs["camera_param"]["hand_camera"]["intrinsic_cv"][1, 1]
    assert np.isclose(fy, 12.0 / np.tan(0.5), rtol=1e-4)
    assert obs in env.observation_space
    env.close()
    venv = ms2.make_vec(
        "PickCube-v0", num_envs=2, obs_mode="pointcloud", camera_cfgs={"width": 8, "height": 8}
    )
    obs, _ = venv.reset(seed=0)
    assert obs["pointcloud"]["xyzw"].shape == (2, 2 * 8 * 8, 4)
    venv.close()


@pytest.mark.parametrize(
    "camera_cfgs, named",
    [
        ({"widht": 64}, "widht"),
        ({"width": 0}, "width"),
        ({"width": "64"}, "width"),
        ({"fov": float("nan")}, "fov"),
        ({"base_camera": {"p": [0.0, 1.0]}}, "p"),
        ({"base_camera": {"colour": 1}}, "colour"),
        ({"side_camera": {"width": 8}}, "side_camera"),
        ({"near": 2.0, "far": 1.0}, "near"),
    ],
)
def test_bad_camera_cfgs_raise_value_error_naming_them(camera_cfgs, named):
    with pytest.raises(ValueError, match=named):
        gym.make("PickCube-v0", obs_mode="rgbd", camera_cfgs=camera_cfgs)


def test_make_vec_batched_images_equal_single_env_images():
    cfgs = {"width": 32, "height": 32}
    venv = ms2.make_vec("PickCube-v0", num_envs=3, obs_mode="rgbd", camera_cfgs=cfgs)
    batched, _ = venv.reset(seed=[5, 6, 7])
    actions = np.stack([venv.single_action_space.sample() for _ in range(3)])
    stepped, *_ = venv.step(actions)
    venv.close()
    for k in range(3):
        env = gym.make("PickCube-v0", obs_mode="rgbd", camera_cfgs=cfgs)
        alone, _ = env.reset(seed=5 + k)
        after, *_ = env.step(actions[k])
        env.close()
        for cam in CAMERAS:
            for key in ("rgb", "depth"):
                got_reset, got_step = batched["image"][cam][key], stepped["image"][cam][key]
                np.testing.assert_array_equal(got_reset[k], alone["image"][cam][key])
                np.testing.assert_array_equal(got_step[k], after["image"][cam][key])
    assert not np.array_equal(
        batched["image"]["base_camera"]["rgb"][0], batched["image"]["base_camera"]["rgb"][1]
    )


def test_make_vec_visual_autoreset_renders_the_new_episode():
    venv = ms2.make_vec(
        "PickCube-v0",
        num_envs=2,
        obs_mode="pointcloud_robot_seg",
        max_episode_steps=1,
        camera_cfgs={"width": 16, "height": 16},
    )
    first, _ = venv.reset(seed=3)
    actions = np.zeros((2, *venv.single_action_space.shape), dtype=np.float32)
    _, _, _, truncated, _ = venv.step(actions)
    assert truncated.all()
    obs, reward, terminated, truncated, _ = venv.step(actions)  # autoreset step
    assert (reward == 0).all() and not terminated.any() and not truncated.any()
    assert obs["pointcloud"]["xyzw"].shape == (2, 2 * 16 * 16, 4)
    assert obs["pointcloud"]["robot_seg"].any()
    # A new episode (seed drawn from each env's generator): the cube moved, so the cloud differs.
    assert not np.array_equal(obs["pointcloud"]["xyzw"], first["pointcloud"]["xyzw"])
    venv.close()


SOFT_TASKS = [i for i in ("Excavate-v0", "Fill-v0") if i in ms2.env_ids()]


@pytest.mark.parametrize("env_id", SOFT_TASKS)
@pytest.mark.parametrize("obs_mode", VISUAL_MODES)
def test_soft_tasks_step_in_every_visual_mode(env_id, obs_mode):
    env = gym.make(env_id, obs_mode=obs_mode, camera_cfgs={"width": 32, "height": 32})
    obs, _ = env.reset(seed=0)
    assert obs in env.observation_space
    obs, *_ = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    assert obs in env.observation_space
    env.close()


def _clay_points(env_id: str, seed: int):
    """(points, rgb, ids) of the clay in a pointcloud_robot_seg observation, and the particles.

    The clay is the segmentation object (channel 1) whose points lie on the particles of the
    same episode (an env in obs mode ``particles`` with the same seed)."""
    env = gym.make(env_id, obs_mode="pointcloud_robot_seg")
    obs, _ = env.reset(seed=seed)
    twin = gym.make(env_id, obs_mode="particles")
    particles = twin.reset(seed=seed)[0]["particles"]["x"]
    cloud = obs["pointcloud"]
    valid = cloud["xyzw"][:, 3] == 1
    xyz, ids = cloud["xyzw"][valid, :3], cloud["Segmentation"][valid]
    # Distance from each point to its nearest particle centre.
    nearest = np.min(np.linalg.norm(xyz[:, None, :] - particles[None, ::2, :], axis=2), axis=1)
    on_clay = nearest < 0.008
    clay_id = np.bincount(ids[on_clay, 1]).argmax()
    assert env.unwrapped.segmentation_ids()["clay"] == clay_id
    clay = ids[:, 1] == clay_id
    assert not cloud["robot_seg"][valid][clay].any(), "clay points are not robot"
    assert len(np.unique(ids[clay, 0])) == 1, "the clay is one visual id"
    return xyz[clay], cloud["rgb"][valid][clay], particles


def test_excavate_point_cloud_shows_the_clay_bed():
    xyz, rgb, particles = _clay_points("Excavate-v0", seed=2)
    assert len(xyz) > 300
    # Every clay point lies on a particle's sphere (radius 4 mm at 5 mm spacing).
    nearest = np.min(np.linalg.norm(xyz[:, None, :] - particles[None, :, :], axis=2), axis=1)
    assert nearest.max() < 0.0055
    # Seen from above: the bed's top surface, terracotta (red over blue).
    assert xyz[:, 2].max() > np.percentile(particles[:, 2], 90)
    assert rgb[:, 0].mean() > rgb[:, 2].mean() + 30


def test_fill_point_cloud_shows_the_clay_in_the_bucket():
    xyz, _rgb, particles = _clay_points("Fill-v0", seed=3)
    assert len(xyz) > 50
    assert np.linalg.norm(xyz.mean(axis=0) - particles.mean(axis=0)) < 0.03


def test_soft_render_rgb_array_shows_the_clay():
    env = gym.make("Excavate-v0", render_mode="rgb_array")
    env.reset(seed=2)
    image = env.render().astype(int)
    env.close()
    # Terracotta pixels (red well above green and blue) where the bed lies.
    clay = (image[..., 0] > image[..., 1] + 40) & (image[..., 0] > image[..., 2] + 60)
    assert clay.sum() > 200


def test_make_vec_soft_env_images_equal_single_env_images():
    cfgs = {"width": 48, "height": 48}
    venv = ms2.make_vec("Excavate-v0", num_envs=2, obs_mode="rgbd", camera_cfgs=cfgs)
    venv.reset(seed=[8, 9])
    actions = np.full((2, *venv.single_action_space.shape), 0.2, dtype=np.float32)
    stepped, *_ = venv.step(actions)
    venv.close()
    for k in range(2):
        env = gym.make("Excavate-v0", obs_mode="rgbd", camera_cfgs=cfgs)
        env.reset(seed=8 + k)
        after, *_ = env.step(actions[k])
        env.close()
        for cam in CAMERAS:
            for key in ("rgb", "depth"):
                got, alone = stepped["image"][cam][key][k], after["image"][cam][key]
                np.testing.assert_array_equal(got, alone)


_SENSOR_SCRIPT = r"""
import sys
import gymnasium as gym
import numpy as np
import ms2

env = gym.make("PickCube-v0", obs_mode="pointcloud")
obs, _ = env.reset(seed=3)
cloud = obs["pointcloud"]
np.savez(sys.argv[1], xyzw=cloud["xyzw"], seg=cloud["Segmentation"][..., 1],
         adapter=np.array(ms2._native.render_adapter()))
"""


def _sensor_images(tmp_path, backend: str) -> dict:
    import os
    import subprocess
    import sys

    out = tmp_path / f"{backend}.npz"
    env = {**os.environ, "MS2_SENSOR_BACKEND": backend}
    subprocess.run([sys.executable, "-c", _SENSOR_SCRIPT, str(out)], check=True, env=env)
    return dict(np.load(out))


def test_ray_cast_and_raster_sensor_paths_agree(tmp_path):
    """The same state seen through both sensor paths (each forced by MS2_SENSOR_BACKEND in a
    fresh process): world points within 1 mm and equal ids except at silhouette edges; the
    ground fills the base camera (no background pixel)."""
    raycast = _sensor_images(tmp_path, "raycast")
    raster = _sensor_images(tmp_path, "raster")
    assert str(raycast["adapter"]).endswith("sensors by Raycast")
    assert str(raster["adapter"]).endswith("sensors by Raster")
    seg_a = raycast["seg"].reshape(2, 128, 128)
    seg_b = raster["seg"].reshape(2, 128, 128)
    # Interior pixels: the 3x3 neighbourhood has one id in both images.
    interior = np.ones_like(seg_a, dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            for seg in (seg_a, seg_b):
                shifted = np.roll(np.roll(seg, dy, axis=1), dx, axis=2)
                interior &= shifted == seg_a
    interior[:, [0, -1], :] = False
    interior[:, :, [0, -1]] = False
    assert interior.mean() > 0.8
    assert (seg_a[interior] == seg_b[interior]).all()
    assert (seg_a != seg_b).mean() < 0.05
    xyz_a = raycast["xyzw"].reshape(2, 128, 128, 4)
    xyz_b = raster["xyzw"].reshape(2, 128, 128, 4)
    gap = np.linalg.norm(xyz_a[..., :3] - xyz_b[..., :3], axis=-1)
    assert np.percentile(gap[interior], 99) < 1e-3, np.percentile(gap[interior], 99)
    # The base camera sees ground or objects at every pixel (ManiSkill2's 20 m ground).
    assert (xyz_a[0, ..., 3] == 1).all() and (xyz_b[0, ..., 3] == 1).all()


def test_turn_faucet_places_maniskill2s_base_camera():
    """TurnFaucet's base_camera looks from (-0.4, 0, 0.3) m at (0, 0, 0.1) m, as ManiSkill2
    places it; the hand camera is the Panda's."""
    env = ms2.Ms2Env(
        "TurnFaucet-v0",
        obs_mode="rgbd",
        render_mode="rgb_array",
        camera_cfgs={"width": 32, "height": 32},
    )
    try:
        obs, _ = env.reset(seed=0)
        eye, target = np.array([-0.4, 0.0, 0.3]), np.array([0.0, 0.0, 0.1])
        pose = obs["camera_param"]["base_camera"]["cam2world_gl"]
        np.testing.assert_allclose(pose[:3, 3], eye, atol=1e-5)
        forward = -pose[:3, 2]  # OpenGL cameras look along -z
        want = (target - eye) / np.linalg.norm(target - eye)
        np.testing.assert_allclose(forward, want, atol=1e-5)
        assert "hand_camera" in obs["camera_param"]
        assert env.render().shape == (512, 512, 3)
    finally:
        env.close()
