"""Images for people: tiling camera images (``render_mode="cameras"``) and writing episode
information onto video frames (``RecordEpisode(info_on_video=True)``).

All functions take and return numpy arrays; images are uint8 ``[H, W, 3]``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

#: Multipliers that spread integer segmentation ids over distinct colours (per RGB channel).
SEGMENTATION_PALETTE = np.array([11, 61, 127], dtype=np.uint32)


def depth_to_image(depth_m: np.ndarray) -> np.ndarray:
    """A grey uint8 [H, W, 3] picture of a depth image (float metres [H, W, 1], 0 = nothing
    seen): 0 m black, the image's largest depth white."""
    depth = np.asarray(depth_m, dtype=np.float32)[..., 0]
    far = float(depth.max()) if depth.size else 0.0
    scaled = np.clip(depth / far, 0.0, 1.0) if far > 0 else np.zeros_like(depth)
    grey = (scaled * 255.0).astype(np.uint8)
    return np.repeat(grey[..., None], 3, axis=-1)


def segmentation_to_image(ids: np.ndarray) -> np.ndarray:
    """A uint8 [H, W, 3] picture of integer ids [H, W] (each id its own colour; 0 black)."""
    ids = np.asarray(ids).astype(np.uint32)
    return ((ids[..., None] * SEGMENTATION_PALETTE) % 256).astype(np.uint8)


def camera_images_to_tiles(cameras: Mapping[str, Mapping[str, np.ndarray]]) -> list[np.ndarray]:
    """The pictures of every camera's images, camera by camera: RGB, depth (grey), and with a
    ``Segmentation`` image its visual-shape and actor/link channels. ``cameras`` is
    ``{uid: {"rgb", "depth", "Segmentation"?}}`` (``Ms2Env``'s native ``camera_images()``, or
    an ``rgbd`` observation's ``obs["image"]``); other keys are skipped."""
    tiles: list[np.ndarray] = []
    for images in cameras.values():
        for key, image in images.items():
            if key == "rgb":
                tiles.append(np.asarray(image, dtype=np.uint8)[..., :3])
            elif key == "depth":
                tiles.append(depth_to_image(image))
            elif key == "Segmentation":
                tiles.append(segmentation_to_image(image[..., 0]))
                tiles.append(segmentation_to_image(image[..., 1]))
    return tiles


def tile_images(images: Sequence[np.ndarray]) -> np.ndarray:
    """One uint8 [H, W, 3] image holding ``images`` (sizes may differ): the tallest first,
    stacked top to bottom in columns as tall as the tallest image (a column holds images of
    one width), columns left to right, the rest black. ``ValueError`` on an empty list."""
    if not images:
        raise ValueError("tile_images needs at least one image")
    ordered = sorted((np.asarray(im) for im in images), key=lambda im: im.shape[0], reverse=True)
    height = ordered[0].shape[0]
    columns: list[list[np.ndarray]] = []
    used = height + 1  # forces a new column for the first image
    for im in ordered:
        if columns and used + im.shape[0] <= height and columns[-1][0].shape[1] == im.shape[1]:
            columns[-1].append(im)
            used += im.shape[0]
        else:
            columns.append([im])
            used = im.shape[0]
    width = sum(col[0].shape[1] for col in columns)
    out = np.zeros((height, width, 3), dtype=np.uint8)
    x = 0
    for col in columns:
        y = 0
        for im in col:
            out[y : y + im.shape[0], x : x + im.shape[1]] = im[..., :3]
            y += im.shape[0]
        x += col[0].shape[1]
    return out


def scalar_info(info: Mapping[str, Any]) -> dict[str, float | int | bool]:
    """The entries of a step's ``info`` that are single numbers or flags (nested dicts are
    searched, their keys joined with ``.``)."""
    out: dict[str, float | int | bool] = {}
    for key, value in info.items():
        if isinstance(value, Mapping):
            out.update({f"{key}.{k}": v for k, v in scalar_info(value).items()})
            continue
        array = np.asarray(value)
        if array.size == 1 and (array.dtype.kind in "biuf"):
            out[key] = array.item()
    return out


def put_text_on_image(image: np.ndarray, lines: Sequence[str]) -> np.ndarray:
    """A copy of ``image`` (uint8 [H, W, 3]) with ``lines`` written top-left in green on a dark
    band (Pillow's built-in font)."""
    from PIL import Image, ImageDraw

    picture = Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8))
    draw = ImageDraw.Draw(picture)
    y = 2
    for line in lines:
        box = draw.textbbox((4, y), line)
        draw.rectangle((box[0] - 2, box[1] - 1, box[2] + 2, box[3] + 1), fill=(0, 0, 0))
        draw.text((4, y), line, fill=(0, 255, 0))
        y = box[3] + 3
    return np.asarray(picture)


def put_info_on_image(
    image: np.ndarray, info: Mapping[str, Any], extras: Sequence[str] = ()
) -> np.ndarray:
    """``image`` with each scalar of ``info`` (``key: value``) and then ``extras`` written on
    it (ManiSkill2's ``info_on_video``)."""

    def fmt(value: float | int | bool) -> str:
        return f"{value:.3f}" if isinstance(value, float) else str(value)

    lines = [f"{k}: {fmt(v)}" for k, v in scalar_info(info).items()]
    return put_text_on_image(image, [*lines, *extras])
