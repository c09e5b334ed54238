"""RL rollouts on Ray: actors holding ``ms2.make_vec`` pools feed a learner (docs/ray.md).

Each :class:`RolloutWorker` is a Ray actor (one CPU) owning a native vector env of
``num_envs`` copies of a task; the driver is the learner. Every iteration it sends each actor
a perturbed copy of a linear policy (``action = tanh(obs @ W)``), gathers the actors' batches
of ``steps`` transitions — ``obs``, ``actions``, ``rewards``, ``dones`` and ``valid`` (false
for the step that auto-resets an env after its episode ended: ``make_vec`` resets on the next
step, ignoring its action) — and moves ``W`` towards the perturbations that earned more reward
(evolution strategies; swap in any learner that consumes batches). The actors run on whichever
nodes of the cluster have a free CPU, so more nodes means more rollouts per second.

    python ms2-py/examples/ray_rollouts.py                           # a local Ray
    python ms2-py/examples/ray_rollouts.py --address 127.0.0.1:6379  # a cluster (ray start)

Needs Ray: ``pip install 'ms2[ray]'``.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
import ray


@ray.remote(num_cpus=1)
class RolloutWorker:
    """A Ray actor stepping a native ``ms2.make_vec`` pool with a linear policy."""

    def __init__(self, env_id: str, num_envs: int, seed: int, control_mode: str) -> None:
        import ms2

        self.env = ms2.make_vec(
            env_id, num_envs=num_envs, obs_mode="state", control_mode=control_mode
        )
        self.obs, _ = self.env.reset(seed=seed)
        self.done = np.zeros(num_envs, dtype=bool)

    def spaces(self) -> tuple[int, int]:
        """(observation size, action size) of one env."""
        return self.obs.shape[1], self.env.single_action_space.shape[0]

    def sample(self, weights: np.ndarray, steps: int) -> dict[str, np.ndarray]:
        """``steps`` transitions of every env under ``action = tanh(obs @ weights)``, each array
        ``[steps, num_envs, ...]``."""
        batch: dict[str, list[Any]] = {k: [] for k in ("obs", "actions", "rewards", "dones")}
        batch["valid"] = []
        for _ in range(steps):
            actions = np.tanh(self.obs @ weights).astype(np.float32)
            obs, rewards, terminated, truncated, _ = self.env.step(actions)
            batch["obs"].append(self.obs)
            batch["actions"].append(actions)
            batch["rewards"].append(rewards)
            batch["valid"].append(~self.done)  # the step after a done only resets the env
            self.done = np.logical_or(terminated, truncated)
            batch["dones"].append(self.done)
            self.obs = obs
        return {k: np.stack(v) for k, v in batch.items()}


def run(
    address: str | None = None,
    env_id: str = "PickCube-v0",
    actors: int = 2,
    num_envs: int = 4,
    steps: int = 50,
    iterations: int = 3,
    sigma: float = 0.1,
    control_mode: str = "pd_ee_delta_pose",
    seed: int = 0,
) -> dict[str, Any]:
    """Runs ``iterations`` of sampling on ``actors`` actors and learning; returns the last
    iteration's batches (one per actor), the learned weights and the transitions per second."""
    if not ray.is_initialized():
        ray.init(address=address, logging_level="WARNING")
    workers = [
        RolloutWorker.remote(env_id, num_envs, seed + 1000 * i, control_mode) for i in range(actors)
    ]
    obs_size, action_size = ray.get(workers[0].spaces.remote())
    rng = np.random.default_rng(seed)
    weights = np.zeros((obs_size, action_size), dtype=np.float32)
    transitions, started = 0, time.perf_counter()
    batches: list[dict[str, np.ndarray]] = []
    for iteration in range(iterations):
        noise = rng.standard_normal((actors, obs_size, action_size)).astype(np.float32)
        batches = ray.get(
            [
                w.sample.remote(weights + sigma * n, steps)
                for w, n in zip(workers, noise, strict=True)
            ]
        )
        returns = np.array([(b["rewards"] * b["valid"]).sum() / b["valid"].sum() for b in batches])
        transitions += sum(b["valid"].sum() for b in batches)
        if returns.std() > 0:
            advantage = (returns - returns.mean()) / returns.std()
            weights += 0.05 / (actors * sigma) * np.tensordot(advantage, noise, axes=1)
        print(f"iteration {iteration}: mean reward per step {returns.mean():.4f}")
    seconds = time.perf_counter() - started
    for worker in workers:
        ray.kill(worker)
    return {
        "batches": batches,
        "weights": weights,
        "transitions_per_second": transitions / seconds,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--address", default=None, help="Ray cluster (default: a local Ray)")
    parser.add_argument("--env-id", default="PickCube-v0")
    parser.add_argument("--actors", type=int, default=2, help="Ray actors (one CPU each)")
    parser.add_argument("--num-envs", type=int, default=4, help="envs per actor's make_vec pool")
    parser.add_argument("--steps", type=int, default=50, help="steps per actor per iteration")
    parser.add_argument("--iterations", type=int, default=3)
    args = parser.parse_args()
    out = run(args.address, args.env_id, args.actors, args.num_envs, args.steps, args.iterations)
    print(f"{out['transitions_per_second']:.0f} transitions/s over {args.actors} actors")


if __name__ == "__main__":
    main()
