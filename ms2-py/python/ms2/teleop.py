"""``ms2 teleop``: drive a robot task's arm from the keyboard in the viewer window and save the
episodes as a trajectory file (ManiSkill2's layout) that ``ms2 replay`` replays.

The env runs in ``pd_ee_delta_pose``: every key press (and auto-repeat while a key is held) is
one env step moving or turning the gripper by a fixed step along an axis of the TCP frame, as
ManiSkill2's ``demo_manual_control`` does; saving, resetting and quitting act once per press
(their auto-repeats are ignored, so a held ``r`` resets once). The simulation advances only on
those keys, so the viewer's pause (``space``) has nothing to pause here; the mouse and the view
keys work as everywhere (docs/viewer.md).
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

#: Keys that translate the TCP: key -> (action index, sign). Axes are the TCP frame's.
TRANSLATE_KEYS = {
    "i": (0, 1.0),
    "k": (0, -1.0),
    "j": (1, 1.0),
    "l": (1, -1.0),
    "u": (2, 1.0),
    "o": (2, -1.0),
}
#: Keys that rotate the TCP: key -> (action index, sign), axis-angle about the TCP's axes.
ROTATE_KEYS = {
    "1": (3, 1.0),
    "2": (3, -1.0),
    "3": (4, 1.0),
    "4": (4, -1.0),
    "5": (5, 1.0),
    "6": (5, -1.0),
}
#: Keys that act once per press: their auto-repeats (a held key) are ignored.
ONCE_KEYS = frozenset({"v", "r", "q", "escape"})

#: Every key of ``ms2 teleop`` and its meaning (printed by ``--help`` and at start).
TELEOP_KEYS = [
    ("i / k", "move the gripper along +x / -x of the TCP frame"),
    ("j / l", "move along +y / -y"),
    ("u / o", "move along +z / -z (z points out of the gripper: u approaches)"),
    ("1 / 2, 3 / 4, 5 / 6", "rotate about +x / -x, +y / -y, +z / -z"),
    ("f / g", "open / close the gripper"),
    ("v", "save the episode to the trajectory file and start a new one"),
    ("r", "reset: discard the episode and start a new one"),
    ("q / escape", "quit (an unsaved episode is discarded)"),
]
VIEW_KEYS = [
    ("mouse", "left drag orbits, right/middle drag (or shift + left) pans, wheel zooms"),
    ("c / m", "cycle free camera and sensor cameras / toggle segmentation"),
]


def keys_help() -> str:
    """The key table as text."""
    rows = TELEOP_KEYS + VIEW_KEYS
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"  {k.ljust(width)}  {meaning}" for k, meaning in rows)


@dataclass
class _Episode:
    """Actions, success flags and states of the episode being driven."""

    seed: int
    env_states: list[np.ndarray]
    soft: bool = False
    actions: list[np.ndarray] = field(default_factory=list)
    success: list[bool] = field(default_factory=list)
    info: dict[str, Any] = field(default_factory=dict)

    def as_record(self, control_mode: str) -> dict[str, Any]:
        """The episode dict :meth:`ms2.trajectory.TrajectoryWriter.append` takes (soft-body
        tasks: the state after reset only, as ManiSkill2 records them)."""
        states = (
            {"env_init_state": np.asarray(self.env_states[0], dtype=np.float32)}
            if self.soft
            else {"env_states": np.stack(self.env_states).astype(np.float32)}
        )
        return {
            "episode_seed": self.seed,
            "control_mode": control_mode,
            "actions": np.asarray(self.actions, dtype=np.float32).reshape(len(self.actions), -1),
            "success": np.asarray(self.success, dtype=np.bool_),
            **states,
            "elapsed_steps": len(self.actions),
            "info": self.info,
        }


@dataclass
class TeleopResult:
    """What a session did: the trajectory file (``None`` if nothing was saved), the saved
    episodes' final success, and the steps taken."""

    output: Path | None
    saved_success: list[bool]
    steps: int


class Teleop:
    """One teleoperation session on ``env_id`` (a robot task), saving to ``output`` (``.h5``).

    Args:
        env_id: the task, e.g. ``"PickCube-v0"``.
        output: trajectory file to write (``X.h5`` and ``X.json``); episodes are appended and
            committed atomically on each save.
        seed: seed of the first episode (then +1 for each new episode).
        translation_step: normalized action per key press for moves (1.0 = 0.1 m).
        rotation_step: normalized action per key press for turns (1.0 = 0.1 rad).
        max_episode_steps: episode limit; ``None`` = the task's.
    """

    def __init__(
        self,
        env_id: str,
        output: str | os.PathLike[str],
        seed: int = 0,
        translation_step: float = 0.1,
        rotation_step: float = 0.3,
        max_episode_steps: int | None = None,
    ) -> None:
        for name, value in (
            ("translation_step", translation_step),
            ("rotation_step", rotation_step),
        ):
            if not (0.0 < value <= 1.0):
                raise ValueError(f"{name} must be in (0, 1] (normalized action), got {value!r}")
        if seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        self.output = Path(output)
        if self.output.suffix != ".h5":
            raise ValueError(f"output must end in .h5, got {str(self.output)!r}")
        kwargs: dict[str, Any] = {}
        if max_episode_steps is not None:
            kwargs["max_episode_steps"] = max_episode_steps
        self.env = gym.make(
            env_id,
            obs_mode="state",
            control_mode="pd_ee_delta_pose",
            render_mode="human",
            **kwargs,
        )
        self.translation_step = translation_step
        self.rotation_step = rotation_step
        self.seed = seed
        self.gripper = 1.0  # open
        self.steps = 0
        self.saved_success: list[bool] = []
        self._writer: Any = None
        self._episode: _Episode | None = None
        self._done = False
        self.viewer: Any = None

    # --- episodes -------------------------------------------------------------------------------

    def _new_episode(self) -> None:
        self.env.reset(seed=self.seed)
        unwrapped = self.env.unwrapped
        self._episode = _Episode(
            self.seed, [unwrapped.get_state()], soft=unwrapped.mpm_freq is not None
        )
        self.seed += 1
        self.gripper = 1.0
        self._done = False

    def _save(self) -> None:
        from .recording import _env_info
        from .trajectory import TrajectoryWriter

        ep = self._episode
        if ep is None or not ep.actions:
            print("nothing to save: the episode has no step yet")
            return
        if self._writer is None:
            self._writer = TrajectoryWriter(self.output, _env_info(self.env))
        self._writer.append(ep.as_record(self.env.unwrapped.control_mode))
        self._writer.commit()
        self.saved_success.append(bool(ep.success[-1]))
        print(
            f"saved episode {len(self.saved_success) - 1} (seed {ep.seed}, {len(ep.actions)} "
            f"steps, success={ep.success[-1]}) to {self.output}"
        )

    def _step(self, action: np.ndarray) -> None:
        if self._done:
            print("the episode is over (limit reached or solved): v saves it, r discards it")
            return
        _, _, terminated, truncated, info = self.env.step(action)
        ep = self._episode
        assert ep is not None
        ep.actions.append(action)
        ep.success.append(bool(info.get("success", False)))
        if not ep.soft:
            ep.env_states.append(self.env.unwrapped.get_state())
        ep.info = {k: v for k, v in info.items() if np.isscalar(v) or isinstance(v, np.generic)}
        self.steps += 1
        self._done = bool(truncated)
        if terminated and not any(ep.success[:-1]):
            print(f"success at step {len(ep.actions)}: v saves the episode")

    # --- keys -----------------------------------------------------------------------------------

    def handle_key(self, key: str, repeat: bool = False) -> bool:
        """Applies one key press; returns ``False`` when the session should end. ``repeat``
        marks the window system's auto-repeat of a held key: it moves, turns and grips again,
        but never saves, resets or quits a second time."""
        if repeat and key in ONCE_KEYS:
            return True
        action = np.zeros(self.env.action_space.shape, dtype=np.float32)
        if key in TRANSLATE_KEYS:
            index, sign = TRANSLATE_KEYS[key]
            action[index] = sign * self.translation_step
        elif key in ROTATE_KEYS:
            index, sign = ROTATE_KEYS[key]
            action[index] = sign * self.rotation_step
        elif key in ("f", "g"):
            self.gripper = 1.0 if key == "f" else -1.0
        elif key == "v":
            self._save()
            self._new_episode()
            return True
        elif key == "r":
            self._new_episode()
            return True
        elif key in ("q", "escape"):
            return False
        else:
            return True
        action[-1] = self.gripper
        self._step(action)
        return True

    def _status(self) -> str:
        ep = self._episode
        steps = len(ep.actions) if ep is not None else 0
        success = bool(ep.success[-1]) if ep is not None and ep.success else False
        gripper = "open" if self.gripper > 0 else "closed"
        return (
            f"seed {self.seed - 1} step {steps} success={success} gripper {gripper} "
            f"saved {len(self.saved_success)} | ijkluo move, 1-6 turn, f/g grip, v save, "
            f"r reset, q quit"
        )

    def run(self, idle_sleep_s: float = 0.01) -> TeleopResult:
        """Runs the session until ``q`` / ``escape`` or the window is closed."""
        print(f"ms2 teleop {self.env.unwrapped.env_id}: keys (in the viewer window)\n{keys_help()}")
        self._new_episode()
        self.viewer = self.env.unwrapped.render_human()
        try:
            running = True
            while running and not self.viewer.closed:
                self.viewer.poll()
                keys = self.viewer.take_key_presses()
                for key, repeat in keys:
                    running = self.handle_key(key, repeat)
                    if not running:
                        break
                self.viewer.set_status(self._status())
                if not self.viewer.closed:
                    self.viewer.draw(self.env.unwrapped._native)
                if not keys:
                    time.sleep(idle_sleep_s)
        finally:
            if self._episode is not None and self._episode.actions:
                print(f"discarded the unsaved episode ({len(self._episode.actions)} steps)")
            if self._writer is not None:
                self._writer.close()
            self.env.close()
        output = self.output if self.saved_success else None
        print(
            f"teleop: {self.steps} steps, {len(self.saved_success)} episodes saved"
            + (f" to {output}" if output else "")
        )
        return TeleopResult(output, self.saved_success, self.steps)


def _cmd_teleop(args: argparse.Namespace) -> int:
    Teleop(
        args.env_id,
        args.output,
        seed=args.seed,
        translation_step=args.translation_step,
        rotation_step=args.rotation_step,
        max_episode_steps=args.max_episode_steps,
    ).run()
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Adds ``ms2 teleop`` to the ``ms2`` command line."""
    p = sub.add_parser(
        "teleop",
        help="drive the arm from the keyboard in the viewer and save a trajectory file",
        description=(
            "Drive a task's arm from the keyboard (pd_ee_delta_pose) in the viewer window and "
            "save episodes as a trajectory file that `ms2 replay` reads. Needs a display."
        ),
        epilog="keys (in the viewer window):\n" + keys_help(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("env_id", help="task id, e.g. PickCube-v0")
    p.add_argument(
        "--output",
        default="teleop/trajectory.h5",
        help="trajectory file to write, .h5 with its .json (default: %(default)s)",
    )
    p.add_argument(
        "--seed", type=int, default=0, help="seed of the first episode, then +1 (default: 0)"
    )
    p.add_argument(
        "--translation-step",
        type=float,
        default=0.1,
        help="normalized action per key press for moves; 1.0 = 0.1 m (default: %(default)s)",
    )
    p.add_argument(
        "--rotation-step",
        type=float,
        default=0.3,
        help="normalized action per key press for turns; 1.0 = 0.1 rad (default: %(default)s)",
    )
    p.add_argument(
        "--max-episode-steps",
        type=int,
        default=None,
        help="episode limit in steps (default: the task's)",
    )
    p.set_defaults(func=_cmd_teleop)


__all__ = ["ONCE_KEYS", "TELEOP_KEYS", "Teleop", "TeleopResult", "add_parser", "keys_help"]
