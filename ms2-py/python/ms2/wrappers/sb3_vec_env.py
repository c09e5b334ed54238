"""stable-baselines3's ``VecEnv`` over :func:`ms2.make_vec` (native threads, no subprocesses).

stable-baselines3 resets a finished env inside the same ``step`` (the new episode's first
observation comes back, the final one goes to ``infos[i]["terminal_observation"]``), while
:class:`ms2.Ms2VectorEnv` follows gymnasium 1.x's next-step autoreset. :class:`SB3VecEnvAdapter`
bridges the two: after a step in which some envs ended it resets exactly those envs
(``reset_mask``), so every action is applied and no step is spent on a reset. It also splits
gymnasium's batched info dict into one dict per env and sets ``"TimeLimit.truncated"``
(truncated and not terminated), as ManiSkill2's ``SB3VecEnvWrapper``.

The adapter implements the whole protocol without importing stable-baselines3 (so it is tested
without torch); :data:`SB3VecEnvWrapper` is the same class with stable-baselines3's ``VecEnv``
as a base, made on first use (an ``ImportError`` naming the package without it)::

    from ms2.wrappers.sb3_vec_env import SB3VecEnvWrapper
    from stable_baselines3 import PPO

    venv = SB3VecEnvWrapper(ms2.make_vec("PickCube-v0", num_envs=8))
    PPO("MlpPolicy", venv).learn(100_000)
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np


def split_vector_info(info: Mapping[str, Any], num_envs: int) -> list[dict[str, Any]]:
    """gymnasium's batched vector info (``{key: array, "_key": mask}``, nested dicts
    included) as one dict per env, holding the keys whose mask is set for that env."""
    out: list[dict[str, Any]] = [{} for _ in range(num_envs)]
    for key, value in info.items():
        if key.startswith("_"):
            continue
        mask = info.get(f"_{key}")
        if isinstance(value, Mapping):
            for i, sub in enumerate(split_vector_info(value, num_envs)):
                if mask is None or mask[i]:
                    out[i][key] = sub
            continue
        for i in range(num_envs):
            if mask is None or mask[i]:
                out[i][key] = value[i]
    return out


def index_obs(obs: Any, i: int) -> Any:
    """Env ``i``'s observation (a copy) from a batched one (array or nested dict)."""
    if isinstance(obs, Mapping):
        return {key: index_obs(value, i) for key, value in obs.items()}
    return np.array(obs[i], copy=True)


class SB3VecEnvAdapter:
    """stable-baselines3's ``VecEnv`` interface over an :class:`ms2.Ms2VectorEnv` ``venv``
    (without stable-baselines3 as a base class; see :data:`SB3VecEnvWrapper`).

    ``observation_space`` / ``action_space`` are one env's spaces, rewards float32, ``dones``
    ``terminated | truncated``; ``seed(s)`` makes the next ``reset()`` seed env ``i`` with
    ``s + i`` (once); later resets of finished envs continue each env's own seed sequence.
    """

    def __init__(self, venv: Any) -> None:
        self.venv = venv
        self.num_envs = int(venv.num_envs)
        self.observation_space = venv.single_observation_space
        self.action_space = venv.single_action_space
        self.render_mode = None
        self.reset_infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        self._next_seed: int | None = None
        self._actions: np.ndarray | None = None

    def seed(self, seed: int | None = None) -> list[int | None]:
        """Seeds the next :meth:`reset`: env ``i`` gets ``seed + i``."""
        self._next_seed = seed
        return [None if seed is None else seed + i for i in range(self.num_envs)]

    def reset(self) -> Any:
        """Resets every env; returns the batched observation (infos in ``reset_infos``)."""
        obs, info = self.venv.reset(seed=self._next_seed)
        self._next_seed = None
        self._actions = None
        self.reset_infos = split_vector_info(info, self.num_envs)
        return obs

    def step_async(self, actions: Any) -> None:
        """Stores the actions (``[num_envs, *action_shape]``) for :meth:`step_wait`."""
        self._actions = np.asarray(actions)

    def step_wait(self) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """Steps every env; envs whose episode ended are reset before returning (their final
        observation in ``infos[i]["terminal_observation"]``). Returns ``(obs, rewards, dones,
        infos)``."""
        if self._actions is None:
            raise RuntimeError("step_wait() called without a pending step_async(actions)")
        actions, self._actions = self._actions, None
        obs, rewards, terminated, truncated, info = self.venv.step(actions)
        infos = split_vector_info(info, self.num_envs)
        dones = np.logical_or(terminated, truncated)
        for i in range(self.num_envs):
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        if dones.any():
            for i in np.flatnonzero(dones):
                infos[i]["terminal_observation"] = index_obs(obs, int(i))
            obs, reset_info = self.venv.reset(options={"reset_mask": dones})
            for i, reset_info_i in enumerate(split_vector_info(reset_info, self.num_envs)):
                if dones[i]:
                    self.reset_infos[i] = reset_info_i
        return obs, np.asarray(rewards, dtype=np.float32), dones, infos

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """:meth:`step_async` then :meth:`step_wait`."""
        self.step_async(actions)
        return self.step_wait()

    def close(self) -> None:
        """Closes the vector env."""
        self.venv.close()

    def _indices(self, indices: int | Iterable[int] | None) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        if isinstance(indices, (int, np.integer)):
            indices = [int(indices)]
        out = [int(i) for i in indices]
        bad = [i for i in out if not 0 <= i < self.num_envs]
        if bad:
            raise ValueError(f"env indices must be in [0, {self.num_envs - 1}], got {bad}")
        return out

    def get_attr(self, attr_name: str, indices: int | Iterable[int] | None = None) -> list[Any]:
        """The attribute of the envs (all copies share the vector env's configuration)."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(
        self, attr_name: str, value: Any, indices: int | Iterable[int] | None = None
    ) -> None:
        """Sets an attribute on the vector env; only for all envs at once (``ValueError``
        otherwise: the copies share one configuration)."""
        if sorted(self._indices(indices)) != list(range(self.num_envs)):
            raise ValueError(f"set_attr({attr_name!r}) applies to all {self.num_envs} envs only")
        setattr(self.venv, attr_name, value)

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: int | Iterable[int] | None = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        """Calls ``venv.<method_name>(i, *args, **kwargs)`` for each env index ``i`` (e.g.
        ``env_method("get_state")``)."""
        method = getattr(self.venv, method_name)
        return [method(i, *method_args, **method_kwargs) for i in self._indices(indices)]

    def env_is_wrapped(
        self, wrapper_class: type, indices: int | Iterable[int] | None = None
    ) -> list[bool]:
        """``False`` for every env: the native envs carry no gymnasium wrappers."""
        return [False for _ in self._indices(indices)]

    def get_images(self) -> list[Any]:
        """Not available: a vector env renders no frames (``NotImplementedError``)."""
        raise NotImplementedError("ms2 vector envs do not render frames")


@functools.cache
def _sb3_vec_env_class() -> type:
    try:
        from stable_baselines3.common.vec_env.base_vec_env import VecEnv
    except ImportError as err:
        raise ImportError(
            "SB3VecEnvWrapper needs stable-baselines3 (pip install stable-baselines3); "
            "SB3VecEnvAdapter has the same interface without it"
        ) from err

    class SB3VecEnvWrapper(SB3VecEnvAdapter, VecEnv):
        """:class:`SB3VecEnvAdapter` as a stable-baselines3 ``VecEnv``."""

        def __init__(self, venv: Any) -> None:
            SB3VecEnvAdapter.__init__(self, venv)
            VecEnv.__init__(
                self, self.num_envs, venv.single_observation_space, venv.single_action_space
            )

    SB3VecEnvWrapper.__module__ = __name__
    return SB3VecEnvWrapper


def __getattr__(name: str) -> Any:
    # SB3VecEnvWrapper is built on first access, importing stable-baselines3 only then.
    if name == "SB3VecEnvWrapper":
        return _sb3_vec_env_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# SB3VecEnvWrapper is left out of __all__: a star import must not pull in stable-baselines3.
__all__ = ["SB3VecEnvAdapter", "index_obs", "split_vector_info"]
