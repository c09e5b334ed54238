"""Shared helpers of the ms2 Python tests."""

from __future__ import annotations

import gymnasium as gym
import ms2
import numpy as np
import pytest

ENV_IDS = ms2.env_ids()
#: The tasks ManiSkill2 users reach for first; every test that loops over tasks covers these.
MANISKILL2_IDS = ["PickCube-v0", "LiftCube-v0", "StackCube-v0"]


def leaves(obs, prefix=""):
    """(path, array) pairs of a (nested dict) observation, in layout order."""
    if isinstance(obs, dict):
        out = []
        for key, value in obs.items():
            out.extend(leaves(value, f"{prefix}/{key}"))
        return out
    return [(prefix or "/", np.asarray(obs))]


def assert_obs_equal(a, b):
    """Observations have the same layout and bit-identical arrays."""
    la, lb = leaves(a), leaves(b)
    assert [p for p, _ in la] == [p for p, _ in lb]
    for (path, x), (_, y) in zip(la, lb, strict=True):
        assert x.dtype == y.dtype, path
        np.testing.assert_array_equal(x, y, err_msg=path)


def obs_differs(a, b) -> bool:
    return any(
        not np.array_equal(x, y) for (_, x), (_, y) in zip(leaves(a), leaves(b), strict=True)
    )


@pytest.fixture(params=MANISKILL2_IDS)
def env_id(request):
    if request.param not in ENV_IDS:
        pytest.fail(f"{request.param} is not registered; registered: {ENV_IDS}")
    return request.param


def make(env_id="PickCube-v0", **kwargs) -> gym.Env:
    """A gymnasium-made env without the passive checker's warnings."""
    return gym.make(env_id, disable_env_checker=True, **kwargs)
