"""Behaviour cloning (an MLP, torch) on ms2 demonstrations with state observations.

Needs the ``baselines`` extra (``pip install ms2[baselines]``: torch, stable-baselines3).
Without ``--demos`` it makes them the ManiSkill2 way, with the ``ms2`` command line:

1. ``ms2 demos generate ENV -n N --policy scripted -c pd_ee_delta_pose --out OUT/demos.h5``
   (seeds 0 .. N-1; the scripted oracle acts in ``pd_ee_delta_pose`` directly);
2. ``ms2 replay --traj-path OUT/demos.h5 -o state --save-traj`` records the state observations
   (``OUT/demos.state.pd_ee_delta_pose.h5``).

It then fits ``action = MLP(obs)`` by mean squared error (``--steps`` gradient steps, batch 256,
as the ManiSkill2 paper's BC baseline), and evaluates the policy on ``--eval-episodes`` seeded
episodes (seeds from 1,000,000 on, none of them a demo's) that end on success or at the time
limit. Writes ``OUT/model.pt`` and ``OUT/summary.json`` (success rate, steps, wall times).

Example (the run in docs/baselines.md)::

    python examples/baselines/bc_state.py --env PickCube-v0 --num-demos 1000 --out runs/bc
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


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env", default="PickCube-v0")
    p.add_argument("--control-mode", default="pd_ee_delta_pose")
    p.add_argument("--demos", type=Path, help="a trajectory file with state obs (else generated)")
    p.add_argument("--num-demos", type=int, default=1000)
    p.add_argument("--steps", type=int, default=20_000, help="gradient steps")
    p.add_argument("--batch-size", type=int, default=256)
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--eval-episodes", type=int, default=100)
    p.add_argument("--eval-envs", type=int, default=10, help="envs of the evaluation make_vec")
    p.add_argument("--max-episode-steps", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--out", type=Path, default=Path("runs/bc_state"))
    return p.parse_args(argv)


def make_demos(args: argparse.Namespace) -> Path:
    """Generates ``--num-demos`` demos and records their state observations; returns the file."""
    raw = args.out / "demos.h5"
    ms2_cli = [sys.executable, "-m", "ms2"]
    subprocess.run(
        [*ms2_cli, "demos", "generate", args.env, "-n", str(args.num_demos), "--policy",
         "scripted", "-c", args.control_mode, "--out", str(raw), "-q"],
        check=True,
    )  # fmt: skip
    subprocess.run(
        [*ms2_cli, "replay", "--traj-path", str(raw), "-o", "state", "--save-traj", "-q"],
        check=True,
    )
    return raw.with_name(f"demos.state.{args.control_mode}.h5")


def load_demos(path: Path, num_demos: int) -> tuple[np.ndarray, np.ndarray]:
    """(obs, actions) pairs of the first ``num_demos`` trajectories: ``obs[t]`` with the
    action taken from it (each trajectory's final observation has no action)."""
    import h5py

    obs, actions = [], []
    with h5py.File(path, "r") as f:
        keys = sorted((k for k in f if k.startswith("traj_")), key=lambda k: int(k[5:]))
        if len(keys) < num_demos:
            raise SystemExit(f"{path} holds {len(keys)} trajectories, fewer than {num_demos}")
        for key in keys[:num_demos]:
            traj = f[key]
            a = np.asarray(traj["actions"], dtype=np.float32)
            obs.append(np.asarray(traj["obs"], dtype=np.float32)[: len(a)])
            actions.append(a)
    return np.concatenate(obs), np.concatenate(actions)


def make_policy(obs_dim: int, act_dim: int) -> Any:
    from torch import nn

    return nn.Sequential(
        nn.Linear(obs_dim, 256), nn.ReLU(),
        nn.Linear(256, 256), nn.ReLU(),
        nn.Linear(256, act_dim), nn.Tanh(),
    )  # fmt: skip


def evaluate(policy: Any, args: argparse.Namespace) -> float:
    """Success rate over ``--eval-episodes`` episodes (seeds ``EVAL_SEED + k``)."""
    import ms2
    import torch

    n = min(args.eval_envs, args.eval_episodes)
    venv = ms2.make_vec(
        args.env,
        num_envs=n,
        obs_mode="state",
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
                with torch.no_grad():
                    action = policy(torch.as_tensor(obs, dtype=torch.float32)).numpy()
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
    obs, actions = load_demos(demos, args.num_demos)
    print(f"{args.num_demos} demos, {len(obs)} (obs, action) pairs, obs dim {obs.shape[1]}")

    policy = make_policy(obs.shape[1], actions.shape[1])
    optim = torch.optim.Adam(policy.parameters(), lr=args.lr)
    obs_t, act_t = torch.from_numpy(obs), torch.from_numpy(actions)
    rng = np.random.default_rng(args.seed)
    t1 = time.perf_counter()
    loss = torch.zeros(())
    for step in range(1, args.steps + 1):
        idx = torch.from_numpy(rng.integers(0, len(obs), size=args.batch_size))
        loss = torch.nn.functional.mse_loss(policy(obs_t[idx]), act_t[idx])
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
        "num_demos": args.num_demos,
        "pairs": len(obs),
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
