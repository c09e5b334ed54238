"""Gymnasium wrappers with ManiSkill2's names.

* :class:`RecordEpisode` (from :mod:`ms2.recording`): videos and trajectory files.
* :class:`FlattenObservationWrapper` and :func:`flatten_dict_keys` (:mod:`.observation`).
* :class:`ContinuousTaskWrapper` and :class:`SuccessInfoWrapper` (:mod:`.sb3`), ManiSkill2's
  wrappers for stable-baselines3 training.
* ``SB3VecEnvWrapper`` (:mod:`.sb3_vec_env`): stable-baselines3's ``VecEnv`` over
  :func:`ms2.make_vec`, imported lazily (stable-baselines3 is optional);
  :class:`SB3VecEnvAdapter` is the same without the stable-baselines3 base class.

Code written for ManiSkill2 imports these from ``mani_skill2.utils.wrappers`` (and its
``observation`` / ``sb3`` submodules), ``mani_skill2.utils.common`` and
``mani_skill2.vector.wrappers.sb3``; with ms2 they all come from here.
"""

from __future__ import annotations

from typing import Any

from ..recording import RecordEpisode
from .observation import FlattenObservationWrapper, flatten_dict_keys
from .sb3 import ContinuousTaskWrapper, SuccessInfoWrapper
from .sb3_vec_env import SB3VecEnvAdapter


def __getattr__(name: str) -> Any:
    # SB3VecEnvWrapper imports stable-baselines3 (and torch): only when asked for.
    if name == "SB3VecEnvWrapper":
        from . import sb3_vec_env

        return sb3_vec_env.SB3VecEnvWrapper
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# SB3VecEnvWrapper is left out of __all__: a star import must not pull in stable-baselines3.
__all__ = [
    "ContinuousTaskWrapper",
    "FlattenObservationWrapper",
    "RecordEpisode",
    "SB3VecEnvAdapter",
    "SuccessInfoWrapper",
    "flatten_dict_keys",
]
