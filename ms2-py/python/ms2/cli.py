"""The ``ms2`` command line (also ``python -m ms2``).

Subcommands:

* ``ms2 envs`` — list the registered tasks.
* ``ms2 run PickCube-v0 --policy scripted|random --episodes 20`` — run episodes and print the
  success rate and env steps/s.
* ``ms2 bench`` — env steps/s and peak memory of a single env and of ``make_vec`` with 1-16 envs.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence


def _cmd_envs(_args: argparse.Namespace) -> int:
    import ms2

    for env_id in ms2.env_ids():
        print(env_id)
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    import gymnasium as gym

    import ms2

    control_mode = args.control_mode
    if control_mode is None:
        supported = ms2.Ms2Env(args.env_id).supported_control_modes
        control_mode = "pd_ee_delta_pose" if "pd_ee_delta_pose" in supported else None
    env = gym.make(
        args.env_id,
        obs_mode=args.obs_mode,
        control_mode=control_mode,
        reward_mode=args.reward_mode,
    )
    policy = ms2.ScriptedPolicy(env) if args.policy == "scripted" else None
    env.action_space.seed(args.seed)
    successes = 0
    total_steps = 0
    started = time.perf_counter()
    for episode in range(args.episodes):
        _obs, info = env.reset(seed=args.seed + episode)
        if policy is not None:
            policy.reset()
        episode_return = 0.0
        success = False
        while True:
            action = policy.act() if policy is not None else env.action_space.sample()
            _obs, reward, terminated, truncated, info = env.step(action)
            total_steps += 1
            episode_return += float(reward)
            success = success or bool(info.get("success", False))
            if terminated or truncated:
                break
        successes += int(success)
        if args.verbose:
            print(
                f"episode {episode} (seed {args.seed + episode}): "
                f"{'success' if success else 'failure'} after {info.get('elapsed_steps', '?')} "
                f"steps, return {episode_return:.3f}"
            )
    elapsed = time.perf_counter() - started
    env.close()
    control_mode = env.unwrapped.control_mode
    print(
        f"{args.env_id} [{control_mode}] {args.policy} policy: success rate "
        f"{successes}/{args.episodes} = {100.0 * successes / max(args.episodes, 1):.1f} %, "
        f"{total_steps} env steps in {elapsed:.2f} s = {total_steps / elapsed:.0f} steps/s"
    )
    return 0


def _add_run_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="run episodes of a task with a scripted or random policy")
    p.add_argument("env_id", nargs="?", default="PickCube-v0", help="task id (default PickCube-v0)")
    p.add_argument("--policy", choices=["scripted", "random"], default="scripted")
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (then +1 each)")
    p.add_argument("--obs-mode", default="state")
    p.add_argument(
        "--control-mode",
        default=None,
        help="default: pd_ee_delta_pose where the robot has it, else the task's default",
    )
    p.add_argument("--reward-mode", default=None)
    p.add_argument("-v", "--verbose", action="store_true", help="print one line per episode")
    p.set_defaults(func=_cmd_run)


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the ``ms2`` command line with ``argv`` (default: ``sys.argv[1:]``)."""
    from . import bench

    parser = argparse.ArgumentParser(prog="ms2", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p_envs = sub.add_parser("envs", help="list the registered tasks")
    p_envs.set_defaults(func=_cmd_envs)
    _add_run_parser(sub)
    bench.add_parser(sub)
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, RuntimeError) as err:
        print(f"ms2 {args.command}: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = ["main"]
