"""Recording episodes (ManiSkill2's ``RecordEpisode``): MP4 videos and trajectory files.

``RecordEpisode`` wraps an ms2 env, with ManiSkill2's semantics. With ``save_video`` (the env
must be made with ``render_mode="rgb_array"`` or ``"cameras"``) it renders one frame after
``reset`` and after every ``step`` (``info_on_video`` writes the step's reward, action and scalar
info on it) and writes each episode to ``<output_dir>/<name_prefix>_<episode id>.mp4``. With
``save_trajectory`` it records each episode's actions, ``success`` flags, observations (unless
the obs mode is ``none``) and ``env.get_state()`` after reset and after every step (soft-body
envs, those with an ``mpm_freq``: the state only after reset, as ManiSkill2's
``env_init_state``; their states hold every particle and replays re-simulate from it), and
appends it to ``<output_dir>/<trajectory_name>.h5`` + ``.json`` in ManiSkill2's layout (see
:mod:`ms2.trajectory`), so ``ms2 replay`` can replay, re-observe and convert it.

An episode is written on the next ``reset`` and on ``close`` (``save_on_reset=True``, the
default; an episode without a step is dropped), or whenever you call :meth:`flush_trajectory` /
:meth:`flush_video` (``save_on_reset=False``). Steps after ``terminated`` / ``truncated``
without a reset stay in the same episode, as in ManiSkill2. Every file is written to a temporary
name and renamed, so a partial file never carries the final name.

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

from .envs import DEFAULT_FILTERED_PAIR_RECYCLING, default_mass_matrix_substeps
from .visualization import put_info_on_image

#: Render modes whose frames ``RecordEpisode`` can save as video.
VIDEO_RENDER_MODES = ("rgb_array", "cameras")


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
            "robot": unwrapped.robot,
            "control_mode": unwrapped.control_mode,
            "reward_mode": unwrapped.reward_mode,
            "sim_freq": unwrapped.sim_freq,
            "control_freq": unwrapped.control_freq,
            **({"mpm_freq": unwrapped.mpm_freq} if unwrapped.mpm_freq is not None else {}),
            **({"exact_restore": True} if getattr(unwrapped, "exact_restore", False) else {}),
            **(
                {"mass_matrix_substeps": unwrapped.mass_matrix_substeps}
                if getattr(unwrapped, "mass_matrix_substeps", None)
                not in (None, default_mass_matrix_substeps(unwrapped.mpm_freq is not None))
                else {}
            ),
            **(
                {"filtered_pair_recycling": unwrapped.filtered_pair_recycling}
                if getattr(unwrapped, "filtered_pair_recycling", None)
                not in (None, DEFAULT_FILTERED_PAIR_RECYCLING)
                else {}
            ),
        },
    }


def _stack_obs(observations: list[Any]) -> Any:
    """Observations of consecutive states (dicts of arrays, or arrays) stacked leaf by leaf into
    one tree with a leading time axis."""
    first = observations[0]
    if isinstance(first, dict):
        return {k: _stack_obs([o[k] for o in observations]) for k in first}
    return np.stack([np.asarray(o) for o in observations])


class _EpisodeLog:
    """Actions, success flags, observations and states of the episode being recorded (``soft``:
    the state after reset only)."""

    def __init__(
        self, episode_id: int, episode_seed: int, first_state: np.ndarray, obs: Any, soft: bool
    ) -> None:
        self.episode_id = episode_id
        self.episode_seed = episode_seed
        self.soft = soft
        self.actions: list[np.ndarray] = []
        self.success: list[bool] = []
        self.env_states: list[np.ndarray] = [first_state]
        self.observations: list[Any] = [obs]
        self.info: dict[str, Any] = {}

    def record_step(self, env: gym.Env, action: Any, obs: Any, info: dict[str, Any]) -> None:
        self.actions.append(np.asarray(action, dtype=np.float32))
        self.success.append(bool(info.get("success", False)))
        self.observations.append(obs)
        if not self.soft:
            self.env_states.append(env.unwrapped.get_state())
        self.info = dict(info)

    def obs_tree(self) -> Any:
        """The stacked observations ``[T+1, ...]`` (an empty dict in obs mode ``none``)."""
        return _stack_obs(self.observations)

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
    """Saves every episode of an ms2 ``env`` as an MP4 video and/or to a trajectory file
    (ManiSkill2's wrapper of the same name and arguments).

    Args:
        env: the env to record (made by ``gymnasium.make`` or :class:`ms2.Ms2Env`).
        output_dir: directory of the videos and the trajectory file (created if missing).
        save_trajectory: append each episode to ``<trajectory_name>.h5`` / ``.json``.
        trajectory_name: file name of the trajectory, without extension.
        save_video: write each episode as an MP4 (needs ``render_mode`` ``"rgb_array"`` or
            ``"cameras"``).
        info_on_video: write each step's scalar ``info`` entries, reward and action on its
            video frame.
        save_on_reset: write the previous episode on ``reset`` and the last one on ``close``
            (episodes without a step are dropped); with ``False`` nothing is written unless
            :meth:`flush_trajectory` / :meth:`flush_video` are called.
        clean_on_close: number the trajectory file's episodes ``traj_0, traj_1, ...`` in the
            order written (ManiSkill2 renames them on close); with ``False`` each keeps the
            wrapper's episode id (one per ``reset``), gaps included.
        name_prefix: video file names are ``<name_prefix>_<episode id>[_<suffix>].mp4``.
        fps: frames per second; ``None`` = the env's control frequency (``render_fps``).
    """

    def __init__(
        self,
        env: gym.Env,
        output_dir: str | os.PathLike[str],
        save_trajectory: bool = True,
        trajectory_name: str = "trajectory",
        save_video: bool = True,
        info_on_video: bool = False,
        save_on_reset: bool = True,
        clean_on_close: bool = True,
        name_prefix: str = "episode",
        fps: float | None = None,
    ) -> None:
        super().__init__(env)
        if save_video and env.render_mode not in VIDEO_RENDER_MODES:
            raise ValueError(
                f"RecordEpisode(save_video=True) needs render_mode in {VIDEO_RENDER_MODES}, got "
                f"{env.render_mode!r}; make the env with render_mode='rgb_array' (or "
                "'cameras') or pass save_video=False"
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
        self.info_on_video = info_on_video
        self.save_on_reset = save_on_reset
        self.clean_on_close = clean_on_close
        self.name_prefix = name_prefix
        self.fps = float(fps if fps is not None else env.metadata.get("render_fps", 20))
        self.video_paths: list[Path] = []
        self.trajectory_path = self.output_dir / f"{trajectory_name}.h5"
        self._frames: list[np.ndarray] = []
        self._episode_id = -1
        self._elapsed_steps = 0
        self._log: _EpisodeLog | None = None
        self._writer: Any = None
        # Steps / frames of the current episode already written by a flush (None: not yet).
        self._flushed_steps: int | None = None
        self._flushed_frames: int | None = None

    def _capture(self, frame_text: tuple[dict[str, Any], list[str]] | None = None) -> None:
        if not self.save_video:
            return
        frame = self.env.render()
        if frame is None:
            return
        frame = np.asarray(frame)
        if frame_text is not None:
            frame = put_info_on_image(frame, frame_text[0], extras=frame_text[1])
        self._frames.append(frame)

    def _write_trajectory(self, log: _EpisodeLog) -> None:
        from .trajectory import TrajectoryWriter

        if self._writer is None:
            self._writer = TrajectoryWriter(self.trajectory_path, _env_info(self.env))
        self._writer.append(
            log.as_episode(self.env.unwrapped.control_mode),
            obs=log.obs_tree(),
            episode_id=None if self.clean_on_close else log.episode_id,
        )
        self._writer.commit()

    def flush_trajectory(
        self, verbose: bool = False, ignore_empty_transition: bool = False
    ) -> None:
        """Writes the episode recorded so far to the trajectory file (also one without a step,
        unless ``ignore_empty_transition``). The episode stays open: later steps are recorded
        into it until the next ``reset``."""
        log = self._log
        if not self.save_trajectory or log is None:
            return
        if ignore_empty_transition and not log.actions:
            return
        if self._flushed_steps == len(log.actions):
            return  # already written as it is (e.g. flushed by hand, then reset)
        self._write_trajectory(log)
        self._flushed_steps = len(log.actions)
        if verbose:
            print(f"Recorded episode {log.episode_id} to {self.trajectory_path}")

    def flush_video(
        self, suffix: str = "", verbose: bool = False, ignore_empty_transition: bool = False
    ) -> Path | None:
        """Writes the frames recorded so far in this episode as
        ``<name_prefix>_<episode id>[_<suffix>].mp4`` (also a single frame, unless
        ``ignore_empty_transition``) and returns its path (``None`` if nothing was written)."""
        if not self.save_video or not self._frames:
            return None
        if ignore_empty_transition and len(self._frames) == 1:
            return None
        if self._flushed_frames == len(self._frames):
            return None  # already written as it is
        name = f"{self.name_prefix}_{max(self._episode_id, 0)}"
        if suffix:
            name += f"_{suffix}"
        path = write_video(self.output_dir / f"{name}.mp4", self._frames, self.fps)
        self._flushed_frames = len(self._frames)
        if path not in self.video_paths:
            self.video_paths.append(path)
        if verbose:
            print(f"Video written: {path}")
        return path

    def flush(self) -> Path | None:
        """Writes the episode recorded so far (trajectory and video, if it has a step) and
        returns the video's path (``None`` without one)."""
        self.flush_trajectory(ignore_empty_transition=True)
        return self.flush_video(ignore_empty_transition=True)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        if self.save_on_reset and self._episode_id >= 0:
            if self._elapsed_steps == 0:
                self._episode_id -= 1  # an episode without a step is dropped: reuse its id
            self.flush()
        self._episode_id += 1
        self._elapsed_steps = 0
        self._frames = []
        self._log = None
        self._flushed_steps = self._flushed_frames = None
        obs, info = self.env.reset(**kwargs)
        self._capture()
        if self.save_trajectory:
            unwrapped = self.env.unwrapped
            self._log = _EpisodeLog(
                self._episode_id,
                int(unwrapped.episode_seed),
                unwrapped.get_state(),
                obs,
                soft=getattr(unwrapped, "mpm_freq", None) is not None,
            )
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._elapsed_steps += 1
        if self.info_on_video:
            flat = np.asarray(action, dtype=np.float64).reshape(-1)
            extras = [
                f"reward: {float(reward):.3f}",
                "action: " + ",".join(f"{x:.2f}" for x in flat),
            ]
            self._capture((info, extras))
        else:
            self._capture()
        if self._log is not None:
            self._log.record_step(self.env, action, obs, info)
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        if self.save_on_reset:
            self.flush()
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        super().close()
