"""Behaviour cloning (a small CNN + MLP, torch) on ms2 demonstrations with RGBD observations.

Needs the ``baselines`` extra (``pip install ms2[baselines]``: torch, stable-baselines3).
The pipeline of ``bc_state.py`` with ``-o rgbd``: without ``--demos`` it runs
``ms2 demos generate ENV -n N --policy scripted -c pd_ee_delta_pose`` then
``ms2 replay -o rgbd --save-traj``. The policy sees both cameras' RGB (scaled to [0, 1]) and
depth (metres, clipped to [0, 4]) stacked as 8 channels, subsampled from 128x128 to 64x64 by
taking every other pixel (``--subsample 1`` keeps 128x128), through three strided
convolutions, joined with the proprioceptive state (``agent/qpos``, ``agent/qvel``,
``extra/*``) before a two-layer MLP head. Fitted by mean squared error, then evaluated on
``--eval-episodes`` seeded episodes (seeds from 1,000,000 on) in ``obs_mode="rgbd"``.

Example (the run in docs/baselines.md)::

    python examples/baselines/bc_rgbd.py --env LiftCube-v0 --num-demos 50 --out runs/bc_rgbd
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bc_common import (  # noqa: E402
    add_common_args,
    demo_trajectories,
    evaluate,
    make_demos,
    train,
    write_summary,
)

CAMERAS = ("base_camera", "hand_camera")
MAX_DEPTH = 4.0


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_args(
        p, env="LiftCube-v0", num_demos=50, steps=1500, batch_size=64, lr=3e-4,
        eval_episodes=20, eval_envs=4, out=Path("runs/bc_rgbd"),
    )  # fmt: skip
    p.add_argument("--subsample", type=int, default=2, help="keep every k-th pixel")
    return p.parse_args(argv)


def split_obs(obs: Any, subsample: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """``(images float16 [T, 8, H / subsample, W / subsample], state float32 [T, S])`` from an
    rgbd observation (an h5py group or a dict of batched arrays)."""
    channels = []
    for cam in CAMERAS:
        image = obs["image"][cam]
        rgb = np.asarray(image["rgb"])[:, ::subsample, ::subsample]
        channels.append(rgb.astype(np.float16) / np.float16(255.0))
        depth = np.asarray(image["depth"], dtype=np.float32)[:, ::subsample, ::subsample]
        depth = np.clip(depth, 0.0, MAX_DEPTH)
        channels.append(depth.astype(np.float16))
    images = np.concatenate(channels, axis=-1).transpose(0, 3, 1, 2)
    extra = [np.asarray(obs["extra"][k], dtype=np.float32) for k in sorted(obs["extra"])]
    state = np.concatenate(
        [np.asarray(obs["agent"]["qpos"]), np.asarray(obs["agent"]["qvel"]), *extra], axis=-1
    ).astype(np.float32)
    return np.ascontiguousarray(images), state


def load_demos(
    path: Path, num_demos: int, subsample: int = 2
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(images, state, actions) of the first ``num_demos`` trajectories (``obs[t]`` with the
    action taken from it)."""
    images, states, actions = [], [], []
    for traj_obs, a in demo_trajectories(path, num_demos):
        im, st = split_obs(traj_obs, subsample)
        images.append(im[: len(a)])
        states.append(st[: len(a)])
        actions.append(a)
    return np.concatenate(images), np.concatenate(states), np.concatenate(actions)


def make_policy(state_dim: int, act_dim: int, image_hw: tuple[int, int] = (64, 64)) -> Any:
    import torch
    from torch import nn

    class RGBDPolicy(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.cnn = nn.Sequential(
                nn.Conv2d(4 * len(CAMERAS), 16, 4, stride=2), nn.ReLU(),
                nn.Conv2d(16, 32, 4, stride=2), nn.ReLU(),
                nn.Conv2d(32, 32, 3, stride=2), nn.ReLU(),
                nn.Flatten(),
            )  # fmt: skip
            with torch.no_grad():
                n = self.cnn(torch.zeros(1, 4 * len(CAMERAS), *image_hw)).shape[1]
            self.head = nn.Sequential(
                nn.Linear(n + state_dim, 256), nn.ReLU(),
                nn.Linear(256, 256), nn.ReLU(),
                nn.Linear(256, act_dim), nn.Tanh(),
            )  # fmt: skip

        def forward(self, images: Any, state: Any) -> Any:
            return self.head(torch.cat([self.cnn(images), state], dim=1))

    return RGBDPolicy()


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    import torch

    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    args.out.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    demos = args.demos if args.demos is not None else make_demos(args, "rgbd")
    demo_s = time.perf_counter() - t0
    images, state, actions = load_demos(demos, args.num_demos, args.subsample)
    print(f"{args.num_demos} demos, {len(actions)} (obs, action) pairs, images {images.shape[1:]}")

    policy = make_policy(state.shape[1], actions.shape[1], images.shape[2:])
    images_t, state_t = torch.from_numpy(images), torch.from_numpy(state)
    act_t = torch.from_numpy(actions)
    final_loss, train_s = train(
        policy,
        lambda idx: torch.nn.functional.mse_loss(
            policy(images_t[idx].float(), state_t[idx]), act_t[idx]
        ),
        len(actions),
        args,
    )
    torch.save(policy.state_dict(), args.out / "model.pt")

    policy.eval()

    def act(obs: Any) -> np.ndarray:
        batch_images, batch_state = split_obs(obs, args.subsample)
        with torch.no_grad():
            return policy(
                torch.from_numpy(batch_images.astype(np.float32)), torch.from_numpy(batch_state)
            ).numpy()

    t2 = time.perf_counter()
    rate = evaluate(act, args, "rgbd")
    return write_summary(
        args,
        {
            "env": args.env,
            "obs_mode": "rgbd",
            "num_demos": args.num_demos,
            "image_hw": list(images.shape[2:]),
            "pairs": len(actions),
            "steps": args.steps,
            "final_loss": final_loss,
            "success_rate": rate,
            "eval_episodes": args.eval_episodes,
            "demo_s": round(demo_s, 1),
            "train_s": round(train_s, 1),
            "eval_s": round(time.perf_counter() - t2, 1),
        },
    )


if __name__ == "__main__":
    main()
