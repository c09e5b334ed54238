"""``ms2 gallery``: one picture per task (the ``render()`` view, goal markers shown), for
``docs/tasks.md``.

Each task is reset with seed 0 and driven by its scripted policy for a few steps (so the robot is
seen at work), then rendered at 512x512 through the env's ``render()`` camera (ManiSkill2's
pose and field of view) and written as ``<out_dir>/<env_id>.png`` (temporary file, then
rename). Tasks without a 3D scene (``Dummy-v0``) are skipped.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

#: Scripted steps taken before the picture (mid-reach for the rigid tasks).
DEFAULT_STEPS = 30


def save_png(path: Path, image: np.ndarray) -> Path:
    """Writes a uint8 [H, W, 3] ``image`` as a PNG at ``path`` atomically."""
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}.png")
    Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8)).save(tmp)
    os.replace(tmp, path)
    return path


def render_task(env_id: str, steps: int = DEFAULT_STEPS, seed: int = 0) -> np.ndarray:
    """The ``render()`` view of ``env_id`` after ``reset(seed)`` and ``steps`` scripted steps."""
    import gymnasium as gym

    from .envs import ScriptedPolicy

    env = gym.make(env_id, obs_mode="none", render_mode="rgb_array")
    try:
        env.reset(seed=seed)
        policy = ScriptedPolicy(env)
        policy.reset()
        for _ in range(steps):
            _, _, terminated, truncated, _ = env.step(policy.act())
            if terminated or truncated:
                break
        return env.render()
    finally:
        env.close()


def render_gallery(
    out_dir: str | os.PathLike[str],
    env_ids: Sequence[str] | None = None,
    steps: int = DEFAULT_STEPS,
    seed: int = 0,
) -> list[Path]:
    """Renders every task with a 3D scene (or ``env_ids``) into ``out_dir``; the PNG paths."""
    import ms2

    specs = {s["env_id"]: s for s in ms2.task_specs()}
    if env_ids is None:
        env_ids = [i for i, s in specs.items() if "rgbd" in s["obs_modes"]]
    unknown = [i for i in env_ids if i not in specs]
    if unknown:
        raise ValueError(f"unknown env ids {unknown}; valid: {sorted(specs)}")
    if steps < 0:
        raise ValueError(f"steps must be non-negative, got {steps}")
    out = Path(out_dir)
    return [save_png(out / f"{i}.png", render_task(i, steps, seed)) for i in env_ids]


__all__ = ["render_gallery", "render_task", "save_png"]
