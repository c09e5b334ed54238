"""ManiSkill2's observation wrapper: :class:`FlattenObservationWrapper`, with
:func:`flatten_dict_keys` (``mani_skill2.utils.wrappers.observation`` and
``mani_skill2.utils.common`` in ManiSkill2).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym
from gymnasium import spaces


def flatten_dict_keys(tree: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """A nested dict as a flat one whose keys are the paths joined with ``/``
    (``{"agent": {"qpos": x}}`` -> ``{"agent/qpos": x}``), leaves in order."""
    out: dict[str, Any] = {}
    for key, value in tree.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten_dict_keys(value, f"{path}/"))
        else:
            out[path] = value
    return out


def flatten_dict_space_keys(space: spaces.Dict, prefix: str = "") -> spaces.Dict:
    """A nested ``Dict`` space as a flat one, keys as :func:`flatten_dict_keys`'s."""
    out: dict[str, spaces.Space] = {}
    for key, sub in space.spaces.items():
        path = f"{prefix}{key}"
        if isinstance(sub, spaces.Dict):
            out.update(flatten_dict_space_keys(sub, f"{path}/").spaces)
        else:
            out[path] = sub
    return spaces.Dict(out)


class FlattenObservationWrapper(gym.ObservationWrapper):
    """Flattens a nested dict observation (and its space) into one level with ``/``-joined
    keys, as ManiSkill2's wrapper of the same name (arrays unchanged; a non-dict observation
    passes through)."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        if isinstance(env.observation_space, spaces.Dict):
            self.observation_space = flatten_dict_space_keys(env.observation_space)

    def observation(self, observation: Any) -> Any:
        if isinstance(observation, Mapping):
            return flatten_dict_keys(observation)
        return observation


__all__ = ["FlattenObservationWrapper", "flatten_dict_keys", "flatten_dict_space_keys"]
