"""ms2: ManiSkill2's robot-manipulation benchmark, reimplemented in Rust, for Python.

``import ms2`` registers the tasks with gymnasium under ManiSkill2's ids::

    import gymnasium as gym
    import ms2

    env = gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    obs, info = env.reset(seed=0)

    envs = ms2.make_vec("PickCube-v0", num_envs=8, obs_mode="state")  # native thread pool

Errors: bad input (unknown ids or modes, wrong action shapes, NaN actions) raises ``ValueError``
naming the bad value and the valid ones; an internal failure of the Rust runtime (including a
panic) raises ``RuntimeError`` and leaves that env unusable.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

import gymnasium as gym

from . import _native
from .envs import Ms2Env, ScriptedPolicy
from .vector import Ms2VectorEnv, make_vec

try:
    __version__ = version("ms2")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0"

__all__ = [
    "Ms2Env",
    "Ms2VectorEnv",
    "ScriptedPolicy",
    "env_ids",
    "make_vec",
    "register_envs",
    "task_specs",
]


def env_ids() -> list[str]:
    """The ids of all ms2 tasks, e.g. ``["PickCube-v0", "LiftCube-v0", "StackCube-v0"]``."""
    return list(_native.env_ids())


def task_specs() -> list[dict]:
    """Every task's static description (read without building an env): ``env_id``,
    ``family``, ``summary``, ``max_episode_steps``, ``robots`` (``robot=`` values, default
    first), ``control_modes`` (empty: all of the robot's), ``default_control_mode``,
    ``obs_modes`` and ``soft_bodies``."""
    return list(_native.task_specs())


def register_envs() -> None:
    """Registers every ms2 task with gymnasium (done on ``import ms2``; idempotent).

    ``gymnasium.make(id, max_episode_steps=N)`` works as for any gymnasium env (the ``TimeLimit``
    wrapper enforces the limit, defaulting to the task's); ``gymnasium.make_vec(id, num_envs=N,
    vectorization_mode="vector_entry_point")`` gives the native :class:`Ms2VectorEnv`.
    """
    for spec in task_specs():
        env_id = spec["env_id"]
        if env_id in gym.registry:
            continue
        gym.register(
            id=env_id,
            entry_point="ms2.envs:make_registered",
            vector_entry_point="ms2.vector:make_vec",
            max_episode_steps=int(spec["max_episode_steps"]),
            kwargs={"env_id": env_id},
            # As ManiSkill2: gymnasium's passive checker refuses the empty observation space of
            # obs_mode="none". Every other mode passes gymnasium's full check_env (tested).
            disable_env_checker=True,
        )


register_envs()
