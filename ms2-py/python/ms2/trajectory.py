"""Trajectory files in ManiSkill2's layout: ``X.h5`` (arrays) plus ``X.json`` (metadata).

``X.h5`` holds one group ``traj_<episode_id>`` per episode:

* ``actions``: float32 ``[T, A]`` in the episode's control mode,
* ``success``: bool ``[T]`` (``info["success"]`` after each step),
* ``env_states``: float32 ``[T+1, S]`` (``env.get_state()`` after reset, then after each step),
  for rigid-body envs; soft-body envs (``mpm_freq`` set: Excavate-v0, Fill-v0) store instead
* ``env_init_state``: float32 ``[S]``, the state after reset only (ManiSkill2's soft-body
  layout; a replay restores it after ``reset(seed)`` and steps the actions),
* ``obs`` (optional): the observations ``[T+1, ...]``; a dict observation becomes nested groups
  (``obs/agent/qpos``, ...), an array observation (``state`` mode) one dataset.

``X.json`` is ``{"env_info": {"env_id", "max_episode_steps", "env_kwargs"}, "episodes":
[{"episode_id", "episode_seed", "reset_kwargs", "control_mode", "elapsed_steps", "info"}]}``.
The JSON is the index: an episode exists once it is listed there.

Writes are atomic: :class:`TrajectoryWriter` builds the next version of both files under
temporary names in the same directory and renames them over the old ones (``.h5`` first, then
``.json``), so a reader never sees a half-written file and an interrupted writer leaves the last
complete version. Opening a missing, truncated or foreign file raises ``FileNotFoundError`` or
:class:`TrajectoryFileError` (a ``ValueError``) naming the file and what is wrong.

    with TrajectoryWriter("demos/PickCube-v0.h5", env_info) as writer:
        writer.append(episode)            # dicts as returned by ms2._native.solve_episodes
        writer.commit()                   # both files now hold every appended episode
    with open_trajectory("demos/PickCube-v0.h5") as traj:
        first = traj.read_episode(0)      # {"actions": ..., "env_states": ..., "success": ...}
        # (soft-body episodes: "env_init_state" instead of "env_states")
"""

from __future__ import annotations

import glob
import json
import os
import shutil
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

ENV_INFO_KEYS = ("env_id", "max_episode_steps", "env_kwargs")
#: Keys every JSON episode entry needs (``reset_kwargs`` is optional: older ManiSkill2 files lack
#: it; it defaults to ``{"seed": episode_seed}``).
EPISODE_KEYS = (
    "episode_id",
    "episode_seed",
    "control_mode",
    "elapsed_steps",
    "info",
)
#: Per-step states (rigid-body episodes) and the state after reset only (soft-body episodes).
STATE_KEYS = ("env_states", "env_init_state")


#: Largest episode seed (and episode id) a trajectory file may hold: seeds are unsigned 64-bit
#: integers (``reset(seed=...)`` accepts ``0 <= seed <= MAX_SEED``).
MAX_SEED = 2**64 - 1


class TrajectoryFileError(ValueError):
    """A trajectory file (or its JSON) is truncated, corrupt or not a trajectory file."""


def json_path_of(h5_path: str | os.PathLike[str]) -> Path:
    """The metadata file of ``X.h5``: ``X.json``."""
    return Path(h5_path).with_suffix(".json")


def _h5py() -> Any:
    try:
        import h5py
    except ImportError as e:  # pragma: no cover - h5py is a dependency
        raise ImportError("trajectory files need h5py: pip install h5py") from e
    return h5py


def _to_json_value(value: Any) -> Any:
    """``value`` with numpy scalars and arrays turned into plain Python (for ``json``)."""
    if isinstance(value, Mapping):
        return {str(k): _to_json_value(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_to_json_value(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _write_obs(group: Any, name: str, obs: Any, steps: int) -> None:
    """Writes an observation tree with ``steps`` rows per leaf under ``group[name]``."""
    if isinstance(obs, Mapping):
        sub = group.create_group(name)
        for key, value in obs.items():
            _write_obs(sub, key, value, steps)
        return
    array = np.asarray(obs)
    if array.shape[:1] != (steps,):
        raise ValueError(
            f"observation {group.name}/{name} has shape {array.shape}; expected {steps} rows "
            "(one per env state)"
        )
    # Images compress well; small vectors are stored plainly (faster to read).
    kwargs = {"compression": "gzip", "compression_opts": 4} if array.ndim >= 3 else {}
    group.create_dataset(name, data=array, **kwargs)


def _read_obs(node: Any) -> Any:
    h5py = _h5py()
    if isinstance(node, h5py.Group):
        return {key: _read_obs(node[key]) for key in node}
    return node[()]


def is_soft_episode(episode: Mapping[str, Any]) -> bool:
    """Whether an episode dict is a soft-body one (``env_init_state``, no ``env_states``)."""
    return "env_init_state" in episode and "env_states" not in episode


def _check_episode_arrays(episode: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, str, Any]:
    """The ``actions``, ``success`` and state array of an episode dict with the state array's
    name (``env_states`` [T+1, S] or, soft-body episodes, ``env_init_state`` [S]), dtypes and
    shapes checked (``ValueError`` naming the episode and the array otherwise)."""
    seed = episode.get("episode_seed", "?")
    present = [k for k in STATE_KEYS if k in episode]
    if len(present) != 1:
        raise ValueError(
            f"episode (seed {seed}): needs exactly one of env_states (rigid-body envs, [T+1, S]) "
            f"and env_init_state (soft-body envs, [S]); it has {present or 'neither'}"
        )
    (state_key,) = present
    actions = np.asarray(episode["actions"])
    success = np.asarray(episode["success"])
    states = np.asarray(episode[state_key])
    if actions.ndim != 2 or actions.dtype != np.float32:
        raise ValueError(
            f"episode (seed {seed}): actions must be float32 [T, A], got {actions.dtype} "
            f"{actions.shape}"
        )
    steps = actions.shape[0]
    if success.shape != (steps,) or success.dtype != np.bool_:
        raise ValueError(
            f"episode (seed {seed}): success must be bool [{steps}], got {success.dtype} "
            f"{success.shape}"
        )
    if state_key == "env_init_state":
        if states.ndim != 1 or states.size == 0 or states.dtype != np.float32:
            raise ValueError(
                f"episode (seed {seed}): env_init_state must be float32 [S] (one state), got "
                f"{states.dtype} {states.shape}"
            )
        if not np.isfinite(states).all():
            raise ValueError(f"episode (seed {seed}): env_init_state holds non-finite values")
    elif states.ndim != 2 or states.shape[0] != steps + 1 or states.dtype != np.float32:
        raise ValueError(
            f"episode (seed {seed}): env_states must be float32 [{steps + 1}, S], got "
            f"{states.dtype} {states.shape}"
        )
    return actions, success, state_key, states


class TrajectoryWriter:
    """Writes episodes to ``X.h5`` + ``X.json``, committing atomically.

    :meth:`append` adds an episode to a working copy (a temporary file next to the target);
    :meth:`commit` renames the working copy over ``X.h5`` and then writes ``X.json``, so after
    each commit both files hold every episode appended so far. Closing without committing
    discards the uncommitted episodes (an interrupted run leaves the last commit).

    Args:
        path: the ``.h5`` path (its ``.json`` sibling is written too).
        env_info: ``{"env_id", "max_episode_steps", "env_kwargs"}``.
    """

    def __init__(self, path: str | os.PathLike[str], env_info: Mapping[str, Any]) -> None:
        missing = [k for k in ENV_INFO_KEYS if k not in env_info]
        if missing:
            raise ValueError(f"env_info lacks {missing}; it needs {list(ENV_INFO_KEYS)}")
        self.path = Path(path)
        if self.path.suffix != ".h5":
            raise ValueError(f"trajectory path must end in .h5, got {str(self.path)!r}")
        check_output_path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        for tmp in stale_temporaries(self.path):
            tmp.unlink(missing_ok=True)
        self.json_path = json_path_of(self.path)
        self.env_info = _to_json_value(dict(env_info))
        self.episodes: list[dict[str, Any]] = []
        self._tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        self._file: Any = None
        self._committed = 0

    def __enter__(self) -> TrajectoryWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _working_file(self) -> Any:
        if self._file is None:
            h5py = _h5py()
            if self._committed and self.path.exists():
                shutil.copyfile(self.path, self._tmp)
                self._file = h5py.File(self._tmp, "a")
            else:
                self._file = h5py.File(self._tmp, "w")
        return self._file

    def append(
        self, episode: Mapping[str, Any], obs: Any = None, episode_id: int | None = None
    ) -> int:
        """Adds one episode (a dict with ``episode_seed``, ``control_mode``, ``actions``,
        ``env_states`` — or ``env_init_state`` for a soft-body episode —, ``success``,
        ``elapsed_steps``, ``info``; optional ``reset_kwargs``) and its observations
        ``[T+1, ...]`` (optional) as group ``traj_<episode_id>`` (``None``: the next number
        after the episodes written so far; a used id raises ``ValueError``). Returns the id."""
        actions, success, state_key, states = _check_episode_arrays(episode)
        if episode_id is None:
            episode_id = max((e["episode_id"] + 1 for e in self.episodes), default=0)
        elif any(e["episode_id"] == episode_id for e in self.episodes):
            raise ValueError(f"episode_id {episode_id} was already written to {self.path}")
        group = self._working_file().create_group(f"traj_{episode_id}")
        group.create_dataset("actions", data=actions)
        group.create_dataset("success", data=success)
        group.create_dataset(state_key, data=states)
        if obs is not None:
            _write_obs(group, "obs", obs, actions.shape[0] + 1)
        seed = int(episode["episode_seed"])
        self.episodes.append(
            {
                "episode_id": episode_id,
                "episode_seed": seed,
                "reset_kwargs": _to_json_value(episode.get("reset_kwargs", {"seed": seed})),
                "control_mode": str(episode["control_mode"]),
                "elapsed_steps": int(episode.get("elapsed_steps", actions.shape[0])),
                "info": _to_json_value(episode.get("info", {})),
            }
        )
        return episode_id

    def commit(self) -> None:
        """Makes every appended episode durable: ``X.h5`` is replaced by the working copy, then
        ``X.json`` (also written to a temporary file and renamed)."""
        if self._file is None and self._committed == 0:
            self._working_file()  # the first commit always writes a fresh (maybe empty) file
        if self._file is not None:
            self._file.flush()
            self._file.close()
            self._file = None
            os.replace(self._tmp, self.path)
        meta = {"env_info": self.env_info, "episodes": self.episodes}
        tmp_json = self.json_path.with_name(f".{self.json_path.name}.{os.getpid()}.tmp")
        with open(tmp_json, "w") as f:
            json.dump(meta, f, indent=2)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp_json, self.json_path)
        self._committed = len(self.episodes)

    def close(self) -> None:
        """Discards uncommitted episodes and removes the working copy."""
        if self._file is not None:
            self._file.close()
            self._file = None
        self._tmp.unlink(missing_ok=True)
        del self.episodes[self._committed :]


class Trajectory:
    """An open trajectory file (see :func:`open_trajectory`). ``env_info`` and ``episodes``
    are the JSON's; :meth:`read_episode` reads one episode's arrays."""

    def __init__(self, path: Path, h5: Any, meta: dict[str, Any]) -> None:
        self.path = path
        self.h5 = h5
        self.env_info: dict[str, Any] = meta["env_info"]
        self.episodes: list[dict[str, Any]] = meta["episodes"]

    def __enter__(self) -> Trajectory:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __len__(self) -> int:
        return len(self.episodes)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        for index in range(len(self.episodes)):
            yield self.read_episode(index)

    def close(self) -> None:
        self.h5.close()

    @property
    def env_id(self) -> str:
        return str(self.env_info["env_id"])

    def is_soft(self, index: int) -> bool:
        """Whether episode ``index`` is a soft-body one (stores ``env_init_state`` only)."""
        group = self.h5[f"traj_{self.episodes[index]['episode_id']}"]
        return "env_init_state" in group and "env_states" not in group

    def read_episode(self, index: int, with_obs: bool = False) -> dict[str, Any]:
        """Episode ``index`` (position in the JSON list): its JSON entry plus ``actions``
        (float32 [T, A]), ``success`` (bool [T]), ``env_states`` (float32 [T+1, S]) — or, for a
        soft-body episode, ``env_init_state`` (float32 [S], the state after reset) — and, with
        ``with_obs``, ``obs`` (``None`` when the file has none)."""
        meta = self.episodes[index]
        name = f"traj_{meta['episode_id']}"
        group = self.h5[name]
        state_key = "env_states" if "env_states" in group else "env_init_state"
        if state_key not in group:
            raise TrajectoryFileError(
                f"{self.path}: episode {name} has neither env_states (rigid-body layout) nor "
                "env_init_state (soft-body layout)"
            )
        try:
            out = dict(meta)
            out.setdefault("reset_kwargs", {"seed": meta["episode_seed"]})
            out["actions"] = np.asarray(group["actions"][()], dtype=np.float32)
            out["success"] = np.asarray(group["success"][()], dtype=np.bool_)
            out[state_key] = np.asarray(group[state_key][()], dtype=np.float32)
            if with_obs:
                out["obs"] = _read_obs(group["obs"]) if "obs" in group else None
        except (KeyError, OSError) as e:
            raise TrajectoryFileError(
                f"{self.path}: episode {name} is unreadable or incomplete ({e})"
            ) from e
        except (ValueError, TypeError) as e:
            raise TrajectoryFileError(
                f"{self.path}: episode {name} holds arrays of the wrong type ({e}); actions and "
                "states must be float32, success bool"
            ) from e
        try:
            _check_episode_arrays(out)
        except ValueError as e:
            raise TrajectoryFileError(f"{self.path}: {name}: {e}") from e
        if int(meta["elapsed_steps"]) != out["actions"].shape[0]:
            raise TrajectoryFileError(
                f"{self.path}: {name}: elapsed_steps in {json_path_of(self.path).name} is "
                f"{meta['elapsed_steps']} but the episode has {out['actions'].shape[0]} actions"
            )
        return out


def _load_meta(json_file: Path, h5_path: Path) -> dict[str, Any]:
    if not json_file.exists():
        raise FileNotFoundError(
            f"{json_file}: metadata file of trajectory {h5_path} not found (every X.h5 needs "
            "its X.json)"
        )
    try:
        with open(json_file) as f:
            meta = json.load(f)
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise TrajectoryFileError(f"{json_file}: not valid JSON (truncated or corrupt: {e})") from e
    if not isinstance(meta, dict) or "env_info" not in meta or "episodes" not in meta:
        raise TrajectoryFileError(
            f"{json_file}: not a trajectory metadata file (expected an object with 'env_info' "
            "and 'episodes')"
        )
    missing = [k for k in ENV_INFO_KEYS if k not in meta["env_info"]]
    if missing:
        raise TrajectoryFileError(f"{json_file}: env_info lacks {missing}")
    if not isinstance(meta["episodes"], list):
        raise TrajectoryFileError(f"{json_file}: 'episodes' must be a list")
    for i, ep in enumerate(meta["episodes"]):
        if not isinstance(ep, dict):
            raise TrajectoryFileError(f"{json_file}: episodes[{i}] must be an object, got {ep!r}")
        missing = [k for k in EPISODE_KEYS if k not in ep]
        if missing:
            raise TrajectoryFileError(f"{json_file}: episodes[{i}] lacks {missing}")
        for key, high in (("episode_id", MAX_SEED), ("episode_seed", MAX_SEED)):
            _check_json_int(json_file, i, key, ep[key], high)
        _check_json_int(json_file, i, "elapsed_steps", ep["elapsed_steps"], 2**31 - 1)
        if not isinstance(ep["control_mode"], str):
            raise TrajectoryFileError(
                f"{json_file}: episodes[{i}]['control_mode'] must be a string, got "
                f"{ep['control_mode']!r}"
            )
    return meta


def _check_json_int(json_file: Path, i: int, key: str, value: Any, high: int) -> None:
    """Refuses a JSON episode entry that is not an int in ``[0, high]``, naming the file."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= high:
        raise TrajectoryFileError(
            f"{json_file}: episodes[{i}]['{key}'] must be an integer in [0, {high}], got {value!r}"
        )


def stale_temporaries(path: Path) -> list[Path]:
    """Working copies (``.X.h5.<pid>.tmp``, ``.X.json.<pid>.tmp``) that a killed writer of
    ``path`` left behind: those whose process no longer runs."""
    stale = []
    for target in (path, json_path_of(path)):
        for tmp in target.parent.glob(f".{glob.escape(target.name)}.*.tmp"):
            pid_text = tmp.name[len(target.name) + 2 : -len(".tmp")]
            if pid_text.isdigit() and not _process_alive(int(pid_text)):
                stale.append(tmp)
    return stale


def _process_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's process
    except OverflowError:
        return False
    return True


def check_output_path(path: Path) -> None:
    """Refuses, before any work, a trajectory output that cannot be written: ``path`` or its
    ``.json`` is a directory, an ancestor is a file, or the nearest existing directory is not
    writable. Raises ``ValueError`` naming the path."""
    for target in (path, json_path_of(path)):
        if target.is_dir():
            raise ValueError(f"output {target} is a directory; give a file path ending in .h5")
    ancestor = path.parent
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise ValueError(f"output {path}: {ancestor} is a file, not a directory")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ValueError(f"output {path}: directory {ancestor} is not writable")


def open_trajectory(path: str | os.PathLike[str]) -> Trajectory:
    """Opens ``X.h5`` and ``X.json`` for reading and checks that they belong together.

    Raises ``FileNotFoundError`` when either file is missing and :class:`TrajectoryFileError`
    (a ``ValueError``) when a file is truncated, corrupt or not a trajectory file; messages
    name the file."""
    h5py = _h5py()
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: trajectory file not found")
    meta = _load_meta(json_path_of(path), path)
    try:
        h5 = h5py.File(path, "r")
    except OSError as e:
        raise TrajectoryFileError(
            f"{path}: not a readable HDF5 trajectory file (truncated or not HDF5: {e})"
        ) from e
    try:
        names = set(h5.keys())
        foreign = sorted(n for n in names if not n.startswith("traj_"))
        if foreign:
            raise TrajectoryFileError(
                f"{path}: not a trajectory file: groups {foreign[:5]} are not 'traj_<id>' episodes"
            )
        absent = [
            f"traj_{ep['episode_id']}"
            for ep in meta["episodes"]
            if f"traj_{ep['episode_id']}" not in names
        ]
        if absent:
            raise TrajectoryFileError(
                f"{path}: {len(absent)} episode(s) listed in {json_path_of(path).name} are "
                f"missing from the file (e.g. {absent[0]}); the file is incomplete"
            )
    except BaseException:
        h5.close()
        raise
    return Trajectory(path, h5, meta)


__all__ = [
    "Trajectory",
    "TrajectoryFileError",
    "TrajectoryWriter",
    "check_output_path",
    "is_soft_episode",
    "json_path_of",
    "open_trajectory",
]
