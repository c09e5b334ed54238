"""What the behaviour-cloning baselines (``bc_state.py``, ``bc_rgbd.py``) share: the command-line
flags, making demos with the ``ms2`` command line, reading their trajectories, the training loop,
the seeded evaluation and the summary file. Each script adds its observation handling and policy.

Demos are made the ManiSkill2 way: ``ms2 demos generate ENV -n N --policy scripted -c MODE``
(seeds 0 .. N-1; the scripted oracle acts in the control mode directly), then
``ms2 replay --traj-path ... -o OBS_MODE --save-traj`` records the observations. Evaluation
episodes use seeds from ``EVAL_SEED`` on (none of them a demo's) and end on success or at the
time limit.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

#: First seed of the evaluation episodes (demos use seeds 0 .. N-1).
EVAL_SEED = 1_000_000


def add_common_args(p: argparse.ArgumentParser, **defaults: Any) -> None:
    """The flags both scripts take; ``defaults`` overrides ``env``, ``num_demos``, ``steps``,
    ``batch_size``, ``lr``, ``eval_episodes``, ``eval_envs`` and ``out``."""
    d = {
        "env": "PickCube-v0", "num_demos": 1000, "steps": 20_000, "batch_size": 256,
        "lr": 1e-3, "eval_episodes": 100, "eval_envs": 10, "out": Path("runs/bc"),
        **defaults,
    }  # fmt: skip
    p.add_argument("--env", default=d["env"])
    p.add_argument("--control-mode", default="pd_ee_delta_pose")
    p.add_argument("--demos", type=Path, help="a trajectory file with the obs (else generated)")
    p.add_argument("--num-demos", type=int, default=d["num_demos"])
    p.add_argument("--steps", type=int, default=d["steps"], help="gradient steps")
    p.add_argument("--batch-size", type=int, default=d["batch_size"])
    p.add_argument("--lr", type=float, default=d["lr"])
    p.add_argument("--eval-episodes", type=int, default=d["eval_episodes"])
    p.add_argument("--eval-envs", type=int, default=d["eval_envs"], help="envs of the evaluation")
    p.add_argument("--max-episode-steps", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--out", type=Path, default=d["out"])


def make_demos(args: argparse.Namespace, obs_mode: str) -> Path:
    """Generates ``--num-demos`` demos and records their ``obs_mode`` observations; returns the
    file with them."""
    raw = args.out / "demos.h5"
    ms2_cli = [sys.executable, "-m", "ms2"]
    subprocess.run(
        [*ms2_cli, "demos", "generate", args.env, "-n", str(args.num_demos), "--policy",
         "scripted", "-c", args.control_mode, "--out", str(raw), "-q"],
        check=True,
    )  # fmt: skip
    subprocess.run(
        [*ms2_cli, "replay", "--traj-path", str(raw), "-o", obs_mode, "--save-traj", "-q"],
        check=True,
    )
    return raw.with_name(f"demos.{obs_mode}.{args.control_mode}.h5")


def demo_trajectories(path: Path, num_demos: int) -> Iterator[tuple[Any, np.ndarray]]:
    """``(obs group, actions [T, A])`` of the first ``num_demos`` trajectories of ``path``
    (``obs`` has T+1 entries: the last one has no action)."""
    import h5py

    with h5py.File(path, "r") as f:
        keys = sorted((k for k in f if k.startswith("traj_")), key=lambda k: int(k[5:]))
        if len(keys) < num_demos:
            raise SystemExit(f"{path} holds {len(keys)} trajectories, fewer than {num_demos}")
        for key in keys[:num_demos]:
            traj = f[key]
            yield traj["obs"], np.asarray(traj["actions"], dtype=np.float32)


def train(
    policy: Any, loss_of: Callable[[Any], Any], pairs: int, args: argparse.Namespace
) -> tuple[float, float]:
    """``--steps`` Adam steps on ``loss_of(batch indices)`` over random batches of the ``pairs``
    (obs, action) pairs; returns (final loss, seconds)."""
    import torch

    optim = torch.optim.Adam(policy.parameters(), lr=args.lr)
    rng = np.random.default_rng(args.seed)
    start = time.perf_counter()
    loss = torch.zeros(())
    for step in range(1, args.steps + 1):
        loss = loss_of(torch.from_numpy(rng.integers(0, pairs, size=args.batch_size)))
        optim.zero_grad()
        loss.backward()
        optim.step()
        if step % max(1, args.steps // 10) == 0:
            print(f"step {step}: loss {loss.item():.5f}", flush=True)
    return float(loss.item()), time.perf_counter() - start


def evaluate(act: Callable[[Any], np.ndarray], args: argparse.Namespace, obs_mode: str) -> float:
    """Success rate of ``act(batched obs) -> actions`` over ``--eval-episodes`` episodes (seeds
    ``EVAL_SEED + k``), ``--eval-envs`` at a time."""
    import ms2

    n = min(args.eval_envs, args.eval_episodes)
    venv = ms2.make_vec(
        args.env,
        num_envs=n,
        obs_mode=obs_mode,
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
                obs, _, terminated, truncated, info = venv.step(act(obs))
                succeeded |= active & np.asarray(info["success"], dtype=bool)
                active &= ~(terminated | truncated)
            successes += int(succeeded[:k].sum())
            done += k
    finally:
        venv.close()
    return successes / args.eval_episodes


def write_summary(args: argparse.Namespace, summary: dict[str, Any]) -> dict[str, Any]:
    """Writes ``OUT/summary.json``, prints it, returns it."""
    (args.out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary), flush=True)
    return summary
