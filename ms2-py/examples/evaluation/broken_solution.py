"""A deliberately broken solution: every episode fails in a different way, to show (and test)
that ``ms2 evaluate`` records each failure with its reason and goes on.

    ms2 evaluate --env-id PickCube-v0 --solution ms2-py/examples/evaluation/broken_solution.py \
        -n 9 --step-time-limit 0.5 -o results/broken

Episode ``i`` (counted over the whole run, also across the fresh policy objects the evaluator
builds after a timeout) does ``MODES[i % len(MODES)]`` on its third step (``reset`` on the
episode's start).
"""

import itertools
import time

import numpy as np
from ms2.evaluation.solution import BasePolicy

#: What episode i does.
MODES = (
    "ok",  # zero actions until the time limit: a normal, unsuccessful episode
    "raise",  # act() raises
    "nan",  # an action with NaN and inf
    "wrong_shape",  # an action with one element too many
    "not_numbers",  # a string instead of an array
    "none",  # act() returns None
    "hang",  # act() sleeps past the per-step time limit
    "reset_raises",  # reset(obs) raises
    "ok",  # after the timeout: a fresh policy object works again
)

#: Seconds the "hang" mode sleeps (longer than the time limit the docs and tests use).
HANG_SECONDS = 2.0

_episodes = itertools.count()


class UserPolicy(BasePolicy):
    """Fails episode i with ``MODES[i % len(MODES)]``."""

    def reset(self, observations):
        self.mode = MODES[next(_episodes) % len(MODES)]
        self.steps = 0
        if self.mode == "reset_raises":
            raise KeyError("no such checkpoint: 'policy.pt'")

    def act(self, observations):
        self.steps += 1
        zero = np.zeros(self.action_space.shape, dtype=np.float32)
        if self.steps < 3 or self.mode == "ok":
            return zero
        if self.mode == "raise":
            raise RuntimeError("the network diverged")
        if self.mode == "nan":
            zero[0], zero[1] = np.nan, np.inf
            return zero
        if self.mode == "wrong_shape":
            return np.zeros(self.action_space.shape[0] + 1, dtype=np.float32)
        if self.mode == "not_numbers":
            return "move left"
        if self.mode == "none":
            return None
        if self.mode == "hang":
            time.sleep(HANG_SECONDS)
            return zero
        raise AssertionError(f"unknown mode {self.mode}")

    @classmethod
    def get_obs_mode(cls, env_id):
        return "state"

    @classmethod
    def get_control_mode(cls, env_id):
        return "pd_ee_delta_pose"
