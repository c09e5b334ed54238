"""ManiSkill2's wrappers for stable-baselines3 training (``mani_skill2.utils.wrappers.sb3``):
:class:`ContinuousTaskWrapper` and :class:`SuccessInfoWrapper`. Neither needs
stable-baselines3; the vector env adapter is :mod:`ms2.wrappers.sb3_vec_env`."""

from __future__ import annotations

from typing import Any

import gymnasium as gym


class ContinuousTaskWrapper(gym.Wrapper):
    """Makes the task continuous (infinite horizon): ``terminated`` is always ``False``, so an
    episode ends only when it is truncated (the time limit). Success still shows in ``info``."""

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, _terminated, truncated, info = super().step(action)
        return obs, reward, False, truncated, info


class SuccessInfoWrapper(gym.Wrapper):
    """Copies ``info["success"]`` to ``info["is_success"]``, the key stable-baselines3's
    logging and evaluation callbacks count successes with."""

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = super().step(action)
        info["is_success"] = info["success"]
        return obs, reward, terminated, truncated, info


__all__ = ["ContinuousTaskWrapper", "SuccessInfoWrapper"]
