"""Recording episodes (ManiSkill2's ``RecordEpisode``): MP4 videos and trajectory files.

``RecordEpisode`` wraps an ms2 env. With ``save_video`` (the env must be made with
``render_mode="rgb_array"``) it renders one frame after ``reset`` and after every ``step`` (the
512x512 human view, goal markers shown) and writes each finished episode to
``<output_dir>/<name_prefix>_<index>.mp4``. With ``save_trajectory`` it records each episode's
actions, ``success`` flags and ``env.get_state()`` after reset and after every step (soft-body
envs, those with an ``mpm_freq``: only after reset, as ManiSkill2's ``env_init_state``; their
states hold every particle and replays re-simulate from it), and appends it to
``<output_dir>/<trajectory_name>.h5`` + ``.json`` in ManiSkill2's layout (see
:mod:`ms2.trajectory`), so ``ms2 replay`` can replay, re-observe and convert it. An episode is
written when it ends (terminated or truncated), on the next ``reset``, or on ``close``; every file
is written to a temporary name and renamed, so a partial file never carries the final name.

Videos need the optional ``video`` extra (``pip install "ms2[video]"``: imageio +
imageio-ffmpeg)::

    env = RecordEpisode(gym.make("PickCube-v0", render_mode="rgb_array"), "videos")
    env.reset(seed=0)
    for _ in range(50):
        env.step(env.action_space.sample())
    env.close()  # videos/episode_0.mp4, videos/trajectory.h5, videos/trajectory.json
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np


def write_video(path: str | os.PathLike[str], frames: Iterable[np.ndarray], fps: float) -> Path:
    """Writes uint8 [H, W, 3] ``frames`` (a list, or any iterable: a generator streams them
    without holding them all) to an H.264 MP4 at ``path`` (temporary file, then rename).
    Returns the path. Raises ``ValueError`` on empty or malformed frames and ``ImportError``
    (naming the ``video`` extra) without imageio-ffmpeg."""
    try:
        import imageio.v2 as imageio
    except ImportError as e:  # pragma: no cover - depends on the installation
        raise ImportError(
            "writing videos needs imageio and imageio-ffmpeg: pip install 'ms2[video]'"
        ) from e
    frames = iter(frames)
    first = next(frames, None)
    if first is None:
        raise ValueError("no frames to write")
    first = np.asarray(first)
    if first.ndim != 3 or first.shape[2] != 3 or first.dtype != np.uint8:
        raise ValueError(f"frames must be uint8 [H, W, 3], got {first.dtype} {first.shape}")
    if not (fps > 0 and np.isfinite(fps)):
        raise ValueError(f"fps must be a positive number, got {fps}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}.mp4")
    writer = imageio.get_writer(tmp, fps=fps, codec="libx264", macro_block_size=16)
    try:
        for frame in itertools.chain([first], frames):
            frame = np.asarray(frame)
            if frame.shape != first.shape or frame.dtype != np.uint8:
                raise ValueError(
                    f"every frame must be uint8 {first.shape}, got {frame.dtype} {frame.shape}"
                )
            writer.append_data(frame)
    except BaseException:
        writer.close()
        tmp.unlink(missing_ok=True)
        raise
    writer.close()
    os.replace(tmp, path)
    return path


def _env_info(env: gym.Env) -> dict[str, Any]:
    """ManiSkill2's ``env_info`` of a trajectory file for ``env``: its id, episode limit and the
    keyword arguments that rebuild it."""
    unwrapped = env.unwrapped
    spec = env.spec
    limit = spec.max_episode_steps if spec is not None else None
    if limit is None:
        limit = unwrapped.max_episode_steps
    return {
        "env_id": spec.id if spec is not None else unwrapped.env_id,
        "max_episode_steps": int(limit),
        "env_kwargs": {
            "obs_mode": unwrapped.obs_mode,
            "control_mode": unwrapped.control_mode,
            "reward_mode": unwrapped.reward_mode,
            "sim_freq": unwrapped.sim_freq,
            "control_freq": unwrapped.control_freq,
            **({"mpm_freq": unwrapped.mpm_freq} if unwrapped.mpm_freq is not None else {}),
        },
    }


class _EpisodeLog:
    """Actions, success flags and states of the episode being recorded (``soft``: the state
    after reset only)."""

    def __init__(self, episode_seed: int, first_state: np.ndarray, soft: bool) -> None:
        self.episode_seed = episode_seed
        self.soft = soft
        self.actions: list[np.ndarray] = []
        self.success: list[bool] = []
        self.env_states: list[np.ndarray] = [first_state]
        self.info: dict[str, Any] = {}

    def record_step(self, env: gym.Env, action: Any, info: dict[str, Any]) -> None:
        self.actions.append(np.asarray(action, dtype=np.float32))
        self.success.append(bool(info.get("success", False)))
        if not self.soft:
            self.env_states.append(env.unwrapped.get_state())
        self.info = dict(info)

    def as_episode(self, control_mode: str) -> dict[str, Any]:
        """The episode dict :meth:`ms2.trajectory.TrajectoryWriter.append` takes."""
        states = (
            {"env_init_state": np.asarray(self.env_states[0], dtype=np.float32)}
            if self.soft
            else {"env_states": np.stack(self.env_states).astype(np.float32)}
        )
        return {
            "episode_seed": self.episode_seed,
            "control_mode": control_mode,
            "actions": np.asarray(self.actions, dtype=np.float32).reshape(len(self.actions), -1),
            "success": np.asarray(self.success, dtype=np.bool_),
            **states,
            "elapsed_steps": len(self.actions),
            "info": self.info,
        }


class RecordEpisode(gym.Wrapper):
    """Saves every episode of an ms2 ``env`` as an MP4 video and/or to a trajectory file.

    Args:
        env: the env to record (made by ``gymnasium.make`` or :class:`ms2.Ms2Env`).
        output_dir: directory of the videos and the trajectory file (created if missing).
        save_trajectory: append each episode to ``<trajectory_name>.h5`` / ``.json``.
        trajectory_name: file name of the trajectory, without extension.
        save_video: write each episode as an MP4 (needs ``render_mode="rgb_array"``).
        name_prefix: video file names are ``<name_prefix>_<episode index>.mp4``.
        fps: frames per second; ``None`` = the env's control frequency (``render_fps``).

    An episode whose recording holds no step (a ``reset`` right after a ``reset``) is dropped.
    """

    def __init__(
        self,
        env: gym.Env,
        output_dir: str | os.PathLike[str],
        save_trajectory: bool = True,
        trajectory_name: str = "trajectory",
        save_video: bool = True,
        name_prefix: str = "episode",
        fps: float | None = None,
    ) -> None:
        super().__init__(env)
        if save_video and env.render_mode != "rgb_array":
            raise ValueError(
                "RecordEpisode(save_video=True) needs render_mode='rgb_array', got "
                f"{env.render_mode!r}; make the env with render_mode='rgb_array' or pass "
                "save_video=False"
            )
        if not hasattr(env.unwrapped, "get_state"):
            raise TypeError(
                f"RecordEpisode records ms2 envs (with get_state), got {type(env.unwrapped)!r}"
            )
        if not trajectory_name or os.sep in trajectory_name:
            raise ValueError(f"trajectory_name must be a plain file name, got {trajectory_name!r}")
        self.output_dir = Path(output_dir)
        self.save_video = save_video
        self.save_trajectory = save_trajectory
        self.name_prefix = name_prefix
        self.fps = float(fps if fps is not None else env.metadata.get("render_fps", 20))
        self.video_paths: list[Path] = []
        self.trajectory_path = self.output_dir / f"{trajectory_name}.h5"
        self._frames: list[np.ndarray] = []
        self._episode = 0
        self._log: _EpisodeLog | None = None
        self._writer: Any = None

    def _capture(self) -> None:
        if not self.save_video:
            return
        frame = self.env.render()
        if frame is not None:
            self._frames.append(np.asarray(frame))

    def _write_trajectory(self, log: _EpisodeLog) -> None:
        from .trajectory import TrajectoryWriter

        if self._writer is None:
            self._writer = TrajectoryWriter(self.trajectory_path, _env_info(self.env))
        self._writer.append(log.as_episode(self.env.unwrapped.control_mode))
        self._writer.commit()

    def flush(self) -> Path | None:
        """Writes the episode recorded so far (video and/or trajectory, if it has any step) and
        starts a new one. Returns the video's path (``None`` without a video)."""
        path = None
        log, self._log = self._log, None
        stepped = log is not None and len(log.actions) > 0
        if self.save_video and self._frames and (stepped or not self.save_trajectory):
            path = self.output_dir / f"{self.name_prefix}_{self._episode}.mp4"
            write_video(path, self._frames, self.fps)
            self.video_paths.append(path)
        if self.save_trajectory and stepped:
            self._write_trajectory(log)
        if path is not None or stepped:
            self._episode += 1
        self._frames = []
        return path

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        self.flush()
        out = self.env.reset(**kwargs)
        self._capture()
        if self.save_trajectory:
            unwrapped = self.env.unwrapped
            self._log = _EpisodeLog(
                int(unwrapped.episode_seed),
                unwrapped.get_state(),
                soft=getattr(unwrapped, "mpm_freq", None) is not None,
            )
        return out

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._capture()
        if self._log is not None:
            self._log.record_step(self.env, action, info)
        if terminated or truncated:
            self.flush()
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        self.flush()
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        super().close()
