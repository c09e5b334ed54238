"""``ms2 gallery``: one PNG per task, written atomically, showing the scene."""

from __future__ import annotations

import numpy as np
from ms2.gallery import render_gallery
from PIL import Image


def test_gallery_writes_one_picture_per_task(tmp_path):
    paths = render_gallery(tmp_path, ["PickCube-v0", "StackCube-v0"], steps=2)
    assert [p.name for p in paths] == ["PickCube-v0.png", "StackCube-v0.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["PickCube-v0.png", "StackCube-v0.png"]
    image = np.asarray(Image.open(paths[0]).convert("RGB"))
    assert image.shape == (512, 512, 3)
    # The scene, not a blank frame: the red cube and the green goal marker are in view.
    red = (image[..., 0] > 150) & (image[..., 1] < 60) & (image[..., 2] < 60)
    green = (image[..., 1] > 150) & (image[..., 0] < 100) & (image[..., 2] < 100)
    assert red.sum() > 20 and green.sum() > 20
