"""Recording episodes to MP4 videos (ManiSkill2's ``RecordEpisode`` video part).

``RecordEpisode`` wraps an env made with ``render_mode="rgb_array"``: it renders one frame after
``reset`` and after every ``step`` (the 512x512 human view, goal markers shown) and writes each
finished episode to ``<output_dir>/<prefix>_<index>.mp4`` when the episode ends (terminated or
truncated), on the next ``reset``, or on ``close``. Videos are written to a temporary file and
renamed, so a partial file never carries the final name.

Needs the optional ``video`` extra (``pip install "ms2[video]"``: imageio + imageio-ffmpeg)::

    env = RecordEpisode(gym.make("PickCube-v0", render_mode="rgb_array"), "videos")
    env.reset(seed=0)
    for _ in range(50):
        env.step(env.action_space.sample())
    env.close()  # videos/episode_0.mp4
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np


def write_video(path: str | os.PathLike[str], frames: list[np.ndarray], fps: float) -> Path:
    """Writes uint8 [H, W, 3] ``frames`` to an H.264 MP4 at ``path`` (temporary file, then
    rename). Returns the path. Raises ``ValueError`` on empty or malformed frames and
    ``ImportError`` (naming the ``video`` extra) without imageio-ffmpeg."""
    try:
        import imageio.v2 as imageio
    except ImportError as e:  # pragma: no cover - depends on the installation
        raise ImportError(
            "writing videos needs imageio and imageio-ffmpeg: pip install 'ms2[video]'"
        ) from e
    if not frames:
        raise ValueError("no frames to write")
    first = np.asarray(frames[0])
    if first.ndim != 3 or first.shape[2] != 3 or first.dtype != np.uint8:
        raise ValueError(f"frames must be uint8 [H, W, 3], got {first.dtype} {first.shape}")
    if not (fps > 0 and np.isfinite(fps)):
        raise ValueError(f"fps must be a positive number, got {fps}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}.mp4")
    writer = imageio.get_writer(tmp, fps=fps, codec="libx264", macro_block_size=16)
    try:
        for frame in frames:
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


class RecordEpisode(gym.Wrapper):
    """Saves every episode of ``env`` (made with ``render_mode="rgb_array"``) as an MP4.

    Args:
        env: the env to record.
        output_dir: directory of the videos (created if missing).
        name_prefix: video file names are ``<name_prefix>_<episode index>.mp4``.
        fps: frames per second; ``None`` = the env's control frequency (``render_fps``).
    """

    def __init__(
        self,
        env: gym.Env,
        output_dir: str | os.PathLike[str],
        name_prefix: str = "episode",
        fps: float | None = None,
    ) -> None:
        super().__init__(env)
        if env.render_mode != "rgb_array":
            raise ValueError(
                f"RecordEpisode needs render_mode='rgb_array', got {env.render_mode!r}"
            )
        self.output_dir = Path(output_dir)
        self.name_prefix = name_prefix
        self.fps = float(fps if fps is not None else env.metadata.get("render_fps", 20))
        self.video_paths: list[Path] = []
        self._frames: list[np.ndarray] = []
        self._episode = 0

    def _capture(self) -> None:
        frame = self.env.render()
        if frame is not None:
            self._frames.append(np.asarray(frame))

    def flush(self) -> Path | None:
        """Writes the frames recorded so far as one video (if any) and starts a new one."""
        if not self._frames:
            return None
        path = self.output_dir / f"{self.name_prefix}_{self._episode}.mp4"
        write_video(path, self._frames, self.fps)
        self._frames = []
        self._episode += 1
        self.video_paths.append(path)
        return path

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        self.flush()
        out = self.env.reset(**kwargs)
        self._capture()
        return out

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._capture()
        if terminated or truncated:
            self.flush()
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        self.flush()
        super().close()
