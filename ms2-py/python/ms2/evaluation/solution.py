"""The submission interface of ManiSkill2's evaluation: the policy class a solution file defines.

A solution is a Python file defining ``UserPolicy``, a subclass of :class:`BasePolicy` (code
written for ManiSkill2 imports it from ``mani_skill2.evaluation.solution``; with ms2 it comes
from ``ms2.evaluation.solution``)::

    import numpy as np
    from ms2.evaluation.solution import BasePolicy

    class UserPolicy(BasePolicy):
        def act(self, observations):
            return np.zeros(self.action_space.shape, dtype=np.float32)

        @classmethod
        def get_obs_mode(cls, env_id):
            return "state"

        @classmethod
        def get_control_mode(cls, env_id):
            return "pd_ee_delta_pose"

The evaluator asks the class for the obs and control modes, makes the env with them, builds
one policy ``UserPolicy(env_id, observation_space, action_space)``, and for every episode calls
``reset(obs)`` after the env's reset and ``act(obs)`` for each step's action.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces


class BasePolicy:
    """The base class of a solution's ``UserPolicy`` (ManiSkill2's interface).

    Args:
        env_id: the task being evaluated, e.g. ``"PickCube-v0"``.
        observation_space: the env's observation space (from the obs mode the class chose).
        action_space: the env's action space (from the control mode the class chose).

    Do not assume that ``gymnasium.make(env_id)`` works inside the policy: the evaluator owns
    the env.
    """

    def __init__(
        self, env_id: str, observation_space: spaces.Space, action_space: spaces.Space
    ) -> None:
        self.env_id = env_id
        self.observation_space = observation_space
        self.action_space = action_space

    def reset(self, observations: Any) -> None:
        """Called with the first observation of every episode (after the env's reset)."""

    def act(self, observations: Any) -> np.ndarray:
        """The action for ``observations``: an array of the action space's shape."""
        raise NotImplementedError(f"{type(self).__name__} must implement act(observations)")

    @classmethod
    def get_obs_mode(cls, env_id: str) -> str:
        """The observation mode the policy needs on ``env_id`` (e.g. ``"state"``, ``"rgbd"``)."""
        raise NotImplementedError(f"{cls.__name__} must implement get_obs_mode(env_id)")

    @classmethod
    def get_control_mode(cls, env_id: str) -> str | None:
        """The control mode the policy acts in on ``env_id``; ``None`` = the task's default."""
        raise NotImplementedError(f"{cls.__name__} must implement get_control_mode(env_id)")


class RandomPolicy(BasePolicy):
    """Uniformly random actions in the task's default control mode, state observations (a
    baseline and a smoke test of the evaluation)."""

    def act(self, observations: Any) -> np.ndarray:
        return self.action_space.sample()

    @classmethod
    def get_obs_mode(cls, env_id: str) -> str:
        return "state"

    @classmethod
    def get_control_mode(cls, env_id: str) -> str | None:
        return None


__all__ = ["BasePolicy", "RandomPolicy"]
