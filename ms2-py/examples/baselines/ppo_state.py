"""PPO (stable-baselines3) on an ms2 task with state observations.

Needs the ``baselines`` extra (``pip install ms2[baselines]``: torch, stable-baselines3).
The recipe is ManiSkill2's SB3 PPO tutorial for LiftCube (state): ``pd_ee_delta_pose``,
``normalized_dense`` rewards, 8 envs, 50-step training episodes, 4,800 env steps per update,
minibatch 400, 15 epochs, gamma 0.8, ``target_kl`` 0.05, two hidden layers of 256. As there the
training task is continuous (``ContinuousTaskWrapper``: success does not end an episode, so the
policy keeps earning the success reward by holding the cube up, still). ``--backend gym`` (the
default) trains on gymnasium envs wrapped that way (stable-baselines3's ``DummyVecEnv``, one
process). ``--backend ms2`` trains over ``SB3VecEnvWrapper(ms2.make_vec(...))`` instead, whose
native episodes end on success: :class:`ContinuousTaskVecEnv` reports that end as a time-limit
truncation, so PPO bootstraps the value of the final observation (the policy never sees what
follows a success, which learns slower; see docs/baselines.md).

Every ``--eval-freq`` env steps the policy (deterministic) is evaluated on ``--eval-episodes``
seeded episodes (seeds from 10,000 + ``--seed``, none seen in training) of at most
``--eval-max-episode-steps`` steps that end on success; one CSV row per evaluation: env steps,
wall seconds, success rate, and the training episodes ended since the previous row with the
fraction of them whose last step was a success, and the mean training reward per step. The
model is saved to ``OUT/model.zip`` at every evaluation. ``--time-limit`` stops training (then
evaluates once more) after that many wall seconds.

Example (the run in docs/baselines.md)::

    python examples/baselines/ppo_state.py --env LiftCube-v0 --total-steps 2000000 --out runs/ppo
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env", default="LiftCube-v0")
    p.add_argument("--control-mode", default="pd_ee_delta_pose")
    p.add_argument("--num-envs", type=int, default=8)
    p.add_argument("--max-episode-steps", type=int, default=50, help="training episode length")
    p.add_argument("--total-steps", type=int, default=400_000, help="env steps of training")
    p.add_argument("--rollout-steps", type=int, default=4800, help="env steps per PPO update")
    p.add_argument("--batch-size", type=int, default=400)
    p.add_argument("--n-epochs", type=int, default=15)
    p.add_argument("--gamma", type=float, default=0.8)
    p.add_argument("--target-kl", type=float, default=0.05)
    p.add_argument("--eval-freq", type=int, default=48_000, help="env steps between evaluations")
    p.add_argument("--eval-episodes", type=int, default=50)
    p.add_argument("--eval-max-episode-steps", type=int, default=100)
    p.add_argument("--time-limit", type=float, default=None, help="training wall seconds")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--backend", choices=["ms2", "gym"], default="gym")
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--out", type=Path, default=Path("runs/ppo_state"))
    return p.parse_args(argv)


def make_continuous_vec_env_class() -> type:
    from ms2.wrappers.sb3_vec_env import SB3VecEnvWrapper

    class ContinuousTaskVecEnv(SB3VecEnvWrapper):
        """``SB3VecEnvWrapper`` whose episodes never terminate: an end by success is reported as
        a truncation (``TimeLimit.truncated``), so PPO bootstraps from the final observation.
        ``is_success`` is set from ``success`` for sb3's logging."""

        def step_wait(self) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
            obs, rewards, dones, infos = super().step_wait()
            for i, info in enumerate(infos):
                info["is_success"] = bool(info.get("success", False))
                if dones[i]:
                    info["TimeLimit.truncated"] = True
            return obs, rewards, dones, infos

    return ContinuousTaskVecEnv


def make_train_env(args: argparse.Namespace) -> Any:
    env_kwargs = dict(
        obs_mode="state",
        control_mode=args.control_mode,
        reward_mode="normalized_dense",
        max_episode_steps=args.max_episode_steps,
    )
    if args.backend == "ms2":
        import ms2

        venv = make_continuous_vec_env_class()(
            ms2.make_vec(args.env, num_envs=args.num_envs, **env_kwargs)
        )
    else:
        import gymnasium as gym
        import ms2  # noqa: F401  (registers the envs)
        from ms2.wrappers import ContinuousTaskWrapper, SuccessInfoWrapper
        from stable_baselines3.common.vec_env import DummyVecEnv

        def make_one() -> Any:
            return SuccessInfoWrapper(ContinuousTaskWrapper(gym.make(args.env, **env_kwargs)))

        venv = DummyVecEnv([make_one for _ in range(args.num_envs)])
    venv.seed(args.seed)
    return venv


def evaluate(model: Any, env_id: str, args: argparse.Namespace, episodes: int, seed: int) -> float:
    """Success rate of the deterministic policy over ``episodes`` seeded episodes (seeds
    ``seed .. seed + episodes - 1``), each ending on success or at the time limit."""
    import ms2

    n = min(episodes, args.num_envs)
    venv = ms2.make_vec(
        env_id,
        num_envs=n,
        obs_mode="state",
        control_mode=args.control_mode,
        reward_mode="normalized_dense",
        max_episode_steps=args.eval_max_episode_steps,
    )
    successes = 0
    done_episodes = 0
    try:
        while done_episodes < episodes:
            k = min(n, episodes - done_episodes)
            obs, _ = venv.reset(seed=seed + done_episodes)
            active = np.zeros(n, dtype=bool)
            active[:k] = True
            succeeded = np.zeros(n, dtype=bool)
            while active.any():
                action, _ = model.predict(obs, deterministic=True)
                obs, _, terminated, truncated, info = venv.step(action)
                succeeded |= active & np.asarray(info["success"], dtype=bool)
                active &= ~(terminated | truncated)
            successes += int(succeeded[:k].sum())
            done_episodes += k
    finally:
        venv.close()
    return successes / episodes


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback

    torch.set_num_threads(args.threads)
    args.out.mkdir(parents=True, exist_ok=True)
    venv = make_train_env(args)
    model = PPO(
        "MlpPolicy",
        venv,
        policy_kwargs=dict(net_arch=[256, 256]),
        n_steps=max(1, args.rollout_steps // args.num_envs),
        batch_size=args.batch_size,
        n_epochs=args.n_epochs,
        gamma=args.gamma,
        target_kl=args.target_kl,
        seed=args.seed,
        device="cpu",
        verbose=0,
    )
    csv_path = args.out / "eval.csv"
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []

    # Training episodes ended since the last evaluation, how many of them on a success, and the
    # sum and count of the training step rewards since then.
    train_episodes = [0, 0]
    train_rewards = [0.0, 0]
    # Wall seconds spent evaluating (unrounded: the CSV's eval_s are rounded).
    eval_seconds = [0.0]

    def train_wall_s() -> float:
        return time.perf_counter() - start - eval_seconds[0]

    def log_eval(env_steps: int) -> None:
        wall_s = train_wall_s()
        eval_start = time.perf_counter()
        rate = evaluate(model, args.env, args, args.eval_episodes, seed=10_000 + args.seed)
        row = {
            "env_steps": env_steps,
            "wall_s": round(wall_s, 1),
            "success_rate": rate,
            "eval_episodes": args.eval_episodes,
            "eval_s": round(time.perf_counter() - eval_start, 1),
            "train_episodes": train_episodes[0],
            "train_success_rate": round(train_episodes[1] / max(1, train_episodes[0]), 4),
            "train_mean_reward": round(train_rewards[0] / max(1, train_rewards[1]), 4),
        }
        train_episodes[:] = [0, 0]
        train_rewards[:] = [0.0, 0]
        rows.append(row)
        with csv_path.open("a" if len(rows) > 1 else "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(row))
            if len(rows) == 1:
                writer.writeheader()
            writer.writerow(row)
        print(json.dumps(row), flush=True)
        model.save(args.out / "model.zip")
        eval_seconds[0] += time.perf_counter() - eval_start

    class EvalCallback(BaseCallback):
        def __init__(self) -> None:
            super().__init__()
            self.next_eval = args.eval_freq

        def _on_step(self) -> bool:
            rewards = np.asarray(self.locals["rewards"], dtype=np.float64)
            train_rewards[0] += float(rewards.sum())
            train_rewards[1] += rewards.size
            for done, info in zip(self.locals["dones"], self.locals["infos"], strict=True):
                if done:
                    train_episodes[0] += 1
                    train_episodes[1] += int(bool(info.get("success", False)))
            if self.num_timesteps >= self.next_eval:
                self.next_eval += args.eval_freq
                log_eval(self.num_timesteps)
            return args.time_limit is None or train_wall_s() < args.time_limit

    log_eval(0)
    model.learn(total_timesteps=args.total_steps, callback=EvalCallback())
    if not rows or rows[-1]["env_steps"] != model.num_timesteps:
        log_eval(model.num_timesteps)
    venv.close()
    summary = {
        "env": args.env,
        "env_steps": model.num_timesteps,
        "train_wall_s": rows[-1]["wall_s"],
        "final_success_rate": rows[-1]["success_rate"],
        "best_success_rate": max(r["success_rate"] for r in rows),
        "eval_episodes": args.eval_episodes,
    }
    (args.out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary), flush=True)
    return summary


if __name__ == "__main__":
    main()
