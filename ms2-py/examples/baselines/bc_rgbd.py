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
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

EVAL_SEED = 1_000_000
CAMERAS = ("base_camera", "hand_camera")
MAX_DEPTH = 4.0


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env", default="LiftCube-v0")
    p.add_argument("--control-mode", default="pd_ee_delta_pose")
    p.add_argument("--demos", type=Path, help="a trajectory file with rgbd obs (else generated)")
    p.add_argument("--num-demos", type=int, default=50)
    p.add_argument("--steps", type=int, default=1500, help="gradient steps")
    p.add_argument("--subsample", type=int, default=2, help="keep every k-th pixel")
    p.add_argument("--batch-size", type=int, default=64)
    p.add_argument("--lr", type=float, default=3e-4)
    p.add_argument("--eval-episodes", type=int, default=20)
    p.add_argument("--eval-envs", type=int, default=4, help="envs of the evaluation make_vec")
    p.add_argument("--max-episode-steps", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--out", type=Path, default=Path("runs/bc_rgbd"))
    return p.parse_args(argv)


def make_demos(args: argparse.Namespace) -> Path:
    """Generates ``--num-demos`` demos and records their RGBD observations; returns the file."""
    raw = args.out / "demos.h5"
    ms2_cli = [sys.executable, "-m", "ms2"]
    subprocess.run(
        [*ms2_cli, "demos", "generate", args.env, "-n", str(args.num_demos), "--policy",
         "scripted", "-c", args.control_mode, "--out", str(raw), "-q"],
        check=True,
    )  # fmt: skip
    subprocess.run(
        [*ms2_cli, "replay", "--traj-path", str(raw), "-o", "rgbd", "--save-traj", "-q"],
        check=True,
    )
    return raw.with_name(f"demos.rgbd.{args.control_mode}.h5")


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
    import h5py

    images, states, actions = [], [], []
    with h5py.File(path, "r") as f:
        keys = sorted((k for k in f if k.startswith("traj_")), key=lambda k: int(k[5:]))
        if len(keys) < num_demos:
            raise SystemExit(f"{path} holds {len(keys)} trajectories, fewer than {num_demos}")
        for key in keys[:num_demos]:
            traj = f[key]
            a = np.asarray(traj["actions"], dtype=np.float32)
            im, st = split_obs(traj["obs"], subsample)
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


def evaluate(policy: Any, args: argparse.Namespace) -> float:
    """Success rate over ``--eval-episodes`` episodes (seeds ``EVAL_SEED + k``)."""
    import ms2
    import torch

    n = min(args.eval_envs, args.eval_episodes)
    venv = ms2.make_vec(
        args.env,
        num_envs=n,
        obs_mode="rgbd",
        control_mode=args.control_mode,
        max_episode_steps=args.max_episode_steps,
    )
    successes = done = 0
    try:
        while done < args.eval_episodes:
            k = min(n, args.eval_episodes - done)
            obs, _ = venv.reset(seed=EVAL_SEED + done)
            active = np.arange(n) < k
            succeeded = np.zeros(n, dtype=bool)
            while active.any():
                images, state = split_obs(obs, args.subsample)
                with torch.no_grad():
                    action = policy(
                        torch.from_numpy(images.astype(np.float32)), torch.from_numpy(state)
                    ).numpy()
                obs, _, terminated, truncated, info = venv.step(action)
                succeeded |= active & np.asarray(info["success"], dtype=bool)
                active &= ~(terminated | truncated)
            successes += int(succeeded[:k].sum())
            done += k
    finally:
        venv.close()
    return successes / args.eval_episodes


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    import torch

    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    args.out.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    demos = args.demos if args.demos is not None else make_demos(args)
    demo_s = time.perf_counter() - t0
    images, state, actions = load_demos(demos, args.num_demos, args.subsample)
    print(f"{args.num_demos} demos, {len(actions)} (obs, action) pairs, images {images.shape[1:]}")

    policy = make_policy(state.shape[1], actions.shape[1], images.shape[2:])
    optim = torch.optim.Adam(policy.parameters(), lr=args.lr)
    images_t, state_t = torch.from_numpy(images), torch.from_numpy(state)
    act_t = torch.from_numpy(actions)
    rng = np.random.default_rng(args.seed)
    t1 = time.perf_counter()
    loss = torch.zeros(())
    for step in range(1, args.steps + 1):
        idx = torch.from_numpy(rng.integers(0, len(actions), size=args.batch_size))
        pred = policy(images_t[idx].float(), state_t[idx])
        loss = torch.nn.functional.mse_loss(pred, act_t[idx])
        optim.zero_grad()
        loss.backward()
        optim.step()
        if step % max(1, args.steps // 10) == 0:
            print(f"step {step}: loss {loss.item():.5f}", flush=True)
    train_s = time.perf_counter() - t1
    torch.save(policy.state_dict(), args.out / "model.pt")

    policy.eval()
    t2 = time.perf_counter()
    rate = evaluate(policy, args)
    summary = {
        "env": args.env,
        "obs_mode": "rgbd",
        "num_demos": args.num_demos,
        "image_hw": list(images.shape[2:]),
        "pairs": len(actions),
        "steps": args.steps,
        "final_loss": float(loss.item()),
        "success_rate": rate,
        "eval_episodes": args.eval_episodes,
        "demo_s": round(demo_s, 1),
        "train_s": round(train_s, 1),
        "eval_s": round(time.perf_counter() - t2, 1),
    }
    (args.out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary), flush=True)
    return summary


if __name__ == "__main__":
    main()
