"""``ms2 bench``: env steps/s and peak memory, single env and ``make_vec``.

Each configuration runs in a fresh Python process (``ms2 bench --worker ...``) so its peak
resident memory is its own. Actions are uniform random within the action space (pre-drawn, so
the timing is the env's), observations are ``state``; episodes that end are reset inside the
timed loop, as a training loop would.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

#: ManiSkill2 0.5.3 measured on the same 2-core machine, PickCube-v0, state obs, 500/20 Hz:
#: single-env steps/s per control mode, and its peak RSS.
MANISKILL2_SINGLE_STEPS_PER_S = {"pd_ee_delta_pose": 556.0, "pd_joint_delta_pos": 648.0}
MANISKILL2_PEAK_RSS_MB = 336.0


def _peak_rss_mb() -> float:
    """This process's peak resident memory in MB (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _random_actions(low: np.ndarray, high: np.ndarray, count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(low, high, size=(count, *low.shape)).astype(np.float32)


def _run_single(env_id: str, control_mode: str, steps: int) -> dict:
    import gymnasium as gym

    import ms2  # noqa: F401  (registers the envs)

    env = gym.make(env_id, obs_mode="state", control_mode=control_mode)
    space = env.action_space
    actions = _random_actions(space.low, space.high, 1024, seed=1)
    env.reset(seed=0)
    for i in range(10):  # warm-up
        env.step(actions[i])
    env.reset(seed=1)
    started = time.perf_counter()
    for i in range(steps):
        _obs, _reward, terminated, truncated, _info = env.step(actions[i % len(actions)])
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - started
    return {"steps_per_s": steps / elapsed, "seconds": elapsed, "env_steps": steps}


def _run_vec(env_id: str, control_mode: str, num_envs: int, steps: int) -> dict:
    import ms2

    envs = ms2.make_vec(env_id, num_envs=num_envs, obs_mode="state", control_mode=control_mode)
    space = envs.single_action_space
    actions = _random_actions(space.low, space.high, 256 * num_envs, seed=1)
    actions = actions.reshape(256, num_envs, *space.shape)
    envs.reset(seed=0)
    for i in range(5):  # warm-up
        envs.step(actions[i])
    batches = max(1, steps // num_envs)
    started = time.perf_counter()
    for i in range(batches):
        envs.step(actions[i % len(actions)])
    elapsed = time.perf_counter() - started
    return {
        "steps_per_s": batches * num_envs / elapsed,
        "seconds": elapsed,
        "env_steps": batches * num_envs,
    }


def _worker(args: argparse.Namespace) -> int:
    spec = json.loads(args.worker)
    if spec["kind"] == "single":
        result = _run_single(spec["env_id"], spec["control_mode"], spec["steps"])
    else:
        result = _run_vec(spec["env_id"], spec["control_mode"], spec["num_envs"], spec["steps"])
    result["peak_rss_mb"] = _peak_rss_mb()
    print(json.dumps(result))
    return 0


def _spawn(spec: dict) -> dict:
    out = subprocess.run(
        [sys.executable, "-m", "ms2", "bench", "--worker", json.dumps(spec)],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def _cmd_bench(args: argparse.Namespace) -> int:
    if args.worker:
        return _worker(args)
    num_envs_list = [int(n) for n in args.num_envs.split(",") if n]
    control_modes = [m for m in args.control_modes.split(",") if m]
    from . import _native

    print(
        f"ms2 bench: {args.env_id}, obs_mode=state, random actions, 500 Hz physics / 20 Hz "
        f"control, {os.cpu_count()} cores, vector pool {_native.num_threads()} threads, "
        f"{args.steps} env steps per row"
    )
    header = (
        f"{'control_mode':<20} {'runner':<18} {'steps/s':>9} {'x our single':>12} "
        f"{'x MS2 single':>12} {'peak RSS MB':>11}"
    )
    print(header)
    print("-" * len(header))
    rows = []
    for control_mode in control_modes:
        single = None
        configs = [("single", 1)] + [("vec", n) for n in num_envs_list]
        for kind, n in configs:
            spec = {
                "kind": kind,
                "env_id": args.env_id,
                "control_mode": control_mode,
                "num_envs": n,
                "steps": args.steps,
            }
            result = _spawn(spec)
            if kind == "single":
                single = result["steps_per_s"]
            peer = MANISKILL2_SINGLE_STEPS_PER_S.get(control_mode)
            runner = "gym.make (1 env)" if kind == "single" else f"make_vec({n})"
            vs_peer = f"{result['steps_per_s'] / peer:.2f}" if peer else "-"
            print(
                f"{control_mode:<20} {runner:<18} {result['steps_per_s']:>9.0f} "
                f"{result['steps_per_s'] / single:>12.2f} {vs_peer:>12} "
                f"{result['peak_rss_mb']:>11.0f}",
                flush=True,
            )
            rows.append({**spec, **result})
    print(
        "ManiSkill2 0.5.3 on this machine (single env): "
        + ", ".join(f"{m} {v:.0f} steps/s" for m, v in MANISKILL2_SINGLE_STEPS_PER_S.items())
        + f", peak RSS {MANISKILL2_PEAK_RSS_MB:.0f} MB"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=2)
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Adds the ``bench`` subcommand to the ``ms2`` command line."""
    p = sub.add_parser("bench", help="benchmark env steps/s (single env and make_vec) and memory")
    p.add_argument("--env-id", default="PickCube-v0")
    p.add_argument("--steps", type=int, default=4000, help="env steps per configuration")
    p.add_argument("--num-envs", default="1,2,4,8,16", help="comma-separated make_vec sizes")
    p.add_argument("--control-modes", default="pd_ee_delta_pose,pd_joint_delta_pos")
    p.add_argument("--json", default=None, help="also write the rows to this JSON file")
    p.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    p.set_defaults(func=_cmd_bench)
