"""Gymnasium spaces from the native space descriptions.

The extension describes a Box as ``("box", shape, low, high, dtype)`` with ``low``/``high`` numpy
arrays, and a Dict as a dict of such descriptions (keys in observation layout order).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces


def to_gym_space(description: Any) -> spaces.Space:
    """The gymnasium space (``Box`` or nested ``Dict`` of ``Box``) for a native description."""
    if isinstance(description, dict):
        # A sequence of pairs keeps the layout order (a plain dict would be sorted by key).
        return spaces.Dict([(key, to_gym_space(value)) for key, value in description.items()])
    kind, shape, low, high, dtype = description
    if kind != "box":
        raise ValueError(f"unknown native space kind {kind!r}; expected 'box'")
    dtype = np.dtype(dtype)
    if dtype == np.bool_:
        # gymnasium has no boolean Box; a 0/1 Box of bool dtype is what MultiBinary would check.
        return spaces.Box(low=0, high=1, shape=tuple(shape), dtype=np.bool_)
    if np.issubdtype(dtype, np.integer):
        # Bounds travel as float32: u32::MAX arrives rounded up to 2**32, which would wrap to 0.
        info = np.iinfo(dtype)
        low = np.clip(np.asarray(low, np.float64), info.min, info.max)
        high = np.clip(np.asarray(high, np.float64), info.min, info.max)
    return spaces.Box(
        low=low.astype(dtype), high=high.astype(dtype), shape=tuple(shape), dtype=dtype
    )
