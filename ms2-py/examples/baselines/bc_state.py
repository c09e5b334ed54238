"""Behaviour cloning (an MLP, torch) on ms2 demonstrations with state observations.

Needs the ``baselines`` extra (``pip install ms2[baselines]``: torch, stable-baselines3).
Without ``--demos`` it makes them the ManiSkill2 way, with the ``ms2`` command line
(``bc_common.py``, shared with ``bc_rgbd.py``):

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


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_args(p, out=Path("runs/bc_state"))
    return p.parse_args(argv)


def load_demos(path: Path, num_demos: int) -> tuple[np.ndarray, np.ndarray]:
    """(obs, actions) pairs of the first ``num_demos`` trajectories: ``obs[t]`` with the
    action taken from it (each trajectory's final observation has no action)."""
    obs, actions = [], []
    for traj_obs, a in demo_trajectories(path, num_demos):
        obs.append(np.asarray(traj_obs, dtype=np.float32)[: len(a)])
        actions.append(a)
    return np.concatenate(obs), np.concatenate(actions)


def make_policy(obs_dim: int, act_dim: int) -> Any:
    from torch import nn

    return nn.Sequential(
        nn.Linear(obs_dim, 256), nn.ReLU(),
        nn.Linear(256, 256), nn.ReLU(),
        nn.Linear(256, act_dim), nn.Tanh(),
    )  # fmt: skip


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    import torch

    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    args.out.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    demos = args.demos if args.demos is not None else make_demos(args, "state")
    demo_s = time.perf_counter() - t0
    obs, actions = load_demos(demos, args.num_demos)
    print(f"{args.num_demos} demos, {len(obs)} (obs, action) pairs, obs dim {obs.shape[1]}")

    policy = make_policy(obs.shape[1], actions.shape[1])
    obs_t, act_t = torch.from_numpy(obs), torch.from_numpy(actions)
    final_loss, train_s = train(
        policy,
        lambda idx: torch.nn.functional.mse_loss(policy(obs_t[idx]), act_t[idx]),
        len(obs),
        args,
    )
    torch.save(policy.state_dict(), args.out / "model.pt")

    policy.eval()

    def act(batch: Any) -> np.ndarray:
        with torch.no_grad():
            return policy(torch.as_tensor(batch, dtype=torch.float32)).numpy()

    t2 = time.perf_counter()
    rate = evaluate(act, args, "state")
    return write_summary(
        args,
        {
            "env": args.env,
            "num_demos": args.num_demos,
            "pairs": len(obs),
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
