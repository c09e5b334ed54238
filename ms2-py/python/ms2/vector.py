"""``Ms2VectorEnv``: N ms2 envs stepped in parallel in native threads, as a gymnasium
``VectorEnv``.

All envs step on the extension's thread pool with the GIL released; observations come back
stacked per key (``[num_envs, ...]`` arrays built in Rust). Sub-envs autoreset in gymnasium 1.x's
default "next step" mode: the step after an episode ends resets that env (its action is ignored)
and returns the first observation of the new episode with reward 0 and both flags false.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _native
from . import assets as _assets
from .envs import MAX_SEED, _Closed, _seed_from, adopt_config, check_options, check_seed, real_array
from .spaces import to_gym_space

#: Most envs one vector env holds (``ms2_tasks::MAX_NUM_ENVS``).
MAX_NUM_ENVS = 4096


class Ms2VectorEnv(VectorEnv):
    """``num_envs`` copies of one ms2 task, stepped in parallel.

    Takes the same keyword arguments as :class:`ms2.envs.Ms2Env`. ``reset(seed=s)`` seeds env
    ``i`` with ``s + i`` (or pass one seed per env); ``options={"reset_mask": mask}`` resets only
    the envs where the boolean ``mask`` is true.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, env_id: str = "PickCube-v0", num_envs: int = 1, **kwargs: Any) -> None:
        if isinstance(num_envs, (bool, np.bool_)) or not isinstance(num_envs, (int, np.integer)):
            raise TypeError(f"num_envs must be an int, got {type(num_envs).__name__} {num_envs!r}")
        if not 1 <= num_envs <= MAX_NUM_ENVS:
            raise ValueError(f"num_envs must be in 1..={MAX_NUM_ENVS}, got {num_envs}")
        _assets.register_installed_packages()
        self._native = _native.NativeVecEnv(env_id, int(num_envs), **kwargs)
        _assets.warn_if_primitive_panda()
        adopt_config(self, self._native.config())
        self.num_envs = int(num_envs)
        self.single_observation_space = to_gym_space(self._native.single_observation_space())
        self.single_action_space = to_gym_space(self._native.single_action_space())
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._seeded = False

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[Any, dict[str, Any]]:
        """Resets all envs (or those in ``options["reset_mask"]``): ``(batched obs, info)``."""
        n = self.num_envs
        options = check_options(options, ("reset_mask",))
        native_reset = self._native.reset  # a closed env raises here
        if seed is None or isinstance(seed, (int, np.integer, bool, np.bool_, float)):
            first = check_seed(seed)
            if first is not None and first + n - 1 > MAX_SEED:
                raise ValueError(
                    f"seed must be in [0, 2**64 - {n}] for {n} envs (env i gets seed + i), "
                    f"got {seed}"
                )
        elif isinstance(seed, Sequence) and not isinstance(seed, (str, bytes)):
            first = None
            if len(seed) != n:
                raise ValueError(f"expected one seed per env ({n}), got {len(seed)}")
        else:
            raise TypeError(
                f"seed must be an int, a sequence of {n} ints/None, or None; got "
                f"{type(seed).__name__} {seed!r}"
            )
        super().reset(seed=first)
        if seed is None:
            if self._seeded:
                seeds: list[int | None] = [None] * n
            else:
                seeds = [_seed_from(self.np_random) for _ in range(n)]
        elif first is not None:
            seeds = [first + i for i in range(n)]
        else:
            seeds = [check_seed(s, f"seed[{i}]") for i, s in enumerate(seed)]
        mask = None
        if "reset_mask" in options:
            mask_array = np.asarray(options["reset_mask"])
            if mask_array.shape != (n,) or mask_array.dtype != np.bool_:
                raise ValueError(
                    f"options['reset_mask'] must be a bool array of shape ({n},), got "
                    f"{mask_array.dtype} {mask_array.shape}"
                )
            mask = mask_array.tolist()
        if any(s is not None for s in seeds):
            self._seeded = True
        return native_reset(seeds, mask)

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Steps all envs with ``actions`` of shape ``(num_envs, *single_action_space.shape)``."""
        native_step = self._native.step  # a closed env raises here
        actions = real_array(actions, "actions")
        if actions.shape != self.action_space.shape:
            raise ValueError(
                f"actions for control_mode {self.control_mode!r} must have shape "
                f"{self.action_space.shape}, got {actions.shape}"
            )
        return native_step(actions.reshape(self.num_envs, -1))

    def get_state(self, index: int) -> np.ndarray:
        """Env ``index``'s simulation state (see :meth:`ms2.envs.Ms2Env.get_state`)."""
        if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"index must be an int, got {type(index).__name__} {index!r}")
        if not 0 <= index < self.num_envs:
            raise ValueError(f"index must be in [0, {self.num_envs - 1}], got {index}")
        return self._native.get_state(int(index))

    def close_extras(self, **kwargs: Any) -> None:
        """Releases the native envs; any later call raises ``ValueError`` (closed)."""
        self._native = _Closed("Ms2VectorEnv")  # type: ignore[assignment]


def make_vec(env_id: str, num_envs: int = 1, **kwargs: Any) -> Ms2VectorEnv:
    """A vector env of ``num_envs`` copies of ``env_id`` stepped in parallel in native threads.

    Keyword arguments are those of ``gymnasium.make`` for ms2 (``obs_mode``, ``control_mode``,
    ``reward_mode``, ``render_mode``, ``sim_freq``, ``control_freq``, ``max_episode_steps``,
    ``camera_cfgs``, ``mpm_freq``). In visual obs modes every env's cameras render in one batch
    per step (one GPU submission through the process's shared renderer).
    """
    return Ms2VectorEnv(env_id, num_envs=num_envs, **kwargs)
