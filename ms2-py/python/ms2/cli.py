"""The ``ms2`` command line (also ``python -m ms2``).

Subcommands:

* ``ms2 envs`` — list the registered tasks.
* ``ms2 run PickCube-v0 --policy scripted|random --episodes 20 [--record DIR]`` — run episodes
  (in the task's default control mode unless ``-c`` is given) and print the success rate and
  env steps/s; ``--record`` saves each episode as an MP4 and to ``DIR/<env_id>.h5`` + ``.json``
  (ManiSkill2's trajectory layout).
* ``ms2 bench`` — env steps/s and peak memory of a single env and of ``make_vec`` with 1-16 envs.
* ``ms2 demos generate PickCube-v0 -n 100 --output demos/PickCube-v0.h5 -w 2`` — write
  successful ``pd_joint_pos`` demonstrations (ManiSkill2's trajectory layout).
* ``ms2 demos bench PickCube-v0 -n 20`` — seconds per generated demo and per converted episode.
* ``ms2 replay --traj-path X.h5 [--obs-mode M] [--target-control-mode C] ...`` — replay or
  convert a trajectory file (ms2's, or one ManiSkill2 0.5.3 wrote), writing
  ``X.<obs_mode>.<control_mode>.h5``.

* ``ms2 gallery`` — one picture per task into ``docs/images/tasks/`` (``docs/tasks.md``).
* ``ms2 evaluate --env-id PickCube-v0 --solution user_solution.py -o results/`` — evaluate a
  solution's ``UserPolicy`` (ManiSkill2's submission interface, ``docs/evaluation.md``);
  ``ms2 leaderboard results_a/ results_b/ -o board.html`` — several results as one HTML table.

Short flags mean the same in every subcommand: ``-n`` how many episodes, ``-o`` obs mode, ``-c``
control mode, ``-w`` worker threads, ``-v`` verbose, ``-q`` no progress bar; except in
``evaluate`` and ``leaderboard``, where ``-o`` is the output, as in ManiSkill2's evaluation.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from typing import Any

from .distributed import add_ray_arguments


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows every option's default: appended as ``(default: X)`` unless the help text
    already says what the default is."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if "default" in text.lower():
            return text
        return super()._get_help_string(action)


def _cmd_envs(_args: argparse.Namespace) -> int:
    import ms2

    for env_id in ms2.env_ids():
        print(env_id)
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    import gymnasium as gym
    from tqdm.auto import tqdm

    import ms2

    if args.env_id not in ms2.env_ids():
        raise ValueError(f"unknown env id {args.env_id!r}; valid ids: {ms2.env_ids()}")
    env = gym.make(
        args.env_id,
        obs_mode=args.obs_mode,
        control_mode=args.control_mode,  # None: the task's own default
        reward_mode=args.reward_mode,
        render_mode="rgb_array" if args.record is not None else None,
    )
    if args.record is not None:
        from .recording import RecordEpisode

        env = RecordEpisode(env, args.record, trajectory_name=args.env_id)
    policy = ms2.ScriptedPolicy(env) if args.policy == "scripted" else None
    env.action_space.seed(args.seed)
    successes = 0
    total_steps = 0
    started = time.perf_counter()
    bar = tqdm(
        total=args.episodes,
        desc=f"run {args.env_id}",
        unit="ep",
        disable=args.quiet or args.episodes < 2,
        dynamic_ncols=True,
    )
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
        bar.update(1)
        bar.set_postfix(success=f"{successes}/{episode + 1}")
        if args.verbose:
            bar.write(
                f"episode {episode} (seed {args.seed + episode}): "
                f"{'success' if success else 'failure'} after {info.get('elapsed_steps', '?')} "
                f"steps, return {episode_return:.3f}"
            )
    bar.close()
    elapsed = time.perf_counter() - started
    control_mode = env.unwrapped.control_mode
    env.close()
    print(
        f"{args.env_id} [{control_mode}] {args.policy} policy: success rate "
        f"{successes}/{args.episodes} = {100.0 * successes / max(args.episodes, 1):.1f} %, "
        f"{total_steps} env steps in {elapsed:.2f} s = {total_steps / elapsed:.0f} steps/s"
        + (" (rendering and recording included)" if args.record is not None else "")
    )
    if args.record is not None:
        print(f"videos: {', '.join(str(p) for p in env.video_paths)}")
        print(f"trajectory: {env.trajectory_path} (+ .json)")
    return 0


def _add_run_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run episodes of a task with a scripted or random policy",
        formatter_class=HelpFormatter,
    )
    p.add_argument("env_id", nargs="?", default="PickCube-v0", help="task id")
    p.add_argument(
        "--policy", choices=["scripted", "random"], default="scripted", help="action source"
    )
    p.add_argument("-n", "--episodes", type=int, default=20, help="number of episodes")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (then +1 each)")
    p.add_argument("-o", "--obs-mode", default="state", help="observation mode")
    p.add_argument(
        "-c",
        "--control-mode",
        default=None,
        help="control mode (None: the task's default, e.g. pd_joint_delta_pos)",
    )
    p.add_argument(
        "--reward-mode", default=None, help="reward mode (None: the task's, normalized_dense)"
    )
    p.add_argument(
        "--record",
        metavar="DIR",
        default=None,
        help="save each episode as DIR/episode_<i>.mp4 and to DIR/<env_id>.h5 + .json",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="print one line per episode")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_run)


def _cmd_demos_generate(args: argparse.Namespace) -> int:
    from . import demos
    from .distributed import ray_options_from_args

    ray = ray_options_from_args(args, num_cpus=args.workers)
    result = demos.generate(
        args.env_id,
        args.num_episodes,
        args.output,
        num_workers=args.workers,
        seed=args.seed,
        max_seeds=args.max_seeds,
        policy=args.policy,
        chunk_size=args.chunk_size,
        progress=not args.quiet,
        control_mode=args.control_mode,
        ray=ray,
    )
    where = f"{args.workers} workers" if ray is None else f"Ray tasks of {args.workers} thread(s)"
    print(
        f"wrote {result.num_episodes} {args.env_id} episodes to {result.path} "
        f"({result.seeds_tried} seeds tried, {result.planner_errors} planner errors) in "
        f"{result.seconds:.1f} s = {result.seconds_per_episode:.3f} s per demo with {where}"
        + (f", {result.resubmitted_chunks} lost chunk(s) resubmitted" if ray is not None else "")
    )
    return 0


def _trajectory_size_summary(path: Any) -> str:
    """The size of trajectory ``path`` and, for soft-body files, what per-step env_states would
    take (float32 [T+1, S] per episode)."""
    from .trajectory import open_trajectory

    size = path.stat().st_size
    with open_trajectory(path) as traj:
        steps = [int(ep["elapsed_steps"]) for ep in traj.episodes]
        soft = [i for i in range(len(traj)) if traj.is_soft(i)]
        state_len = traj.read_episode(soft[0])["env_init_state"].size if soft else 0
    text = f"{size / 1e6:.2f} MB for {len(steps)} episodes ({sum(steps)} steps)"
    if soft:
        per_step = sum(4 * (t + 1) * state_len for t in steps)
        text += (
            f"; soft-body layout (env_init_state of {state_len} floats): per-step env_states "
            f"would take {per_step / 1e6:.1f} MB"
        )
    return text


def _cmd_demos_bench(args: argparse.Namespace) -> int:
    import os
    import tempfile
    from pathlib import Path

    from . import demos

    targets = args.target_control_modes.split(",")
    print(f"load average before: {os.getloadavg()[0]:.1f} (2-core machine figures vary with it)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{args.env_id}.h5"
        gen = demos.generate(
            args.env_id,
            args.num_episodes,
            path,
            num_workers=args.workers,
            policy=args.policy,
            progress=False,
            control_mode=args.control_mode,
        )
        print(
            f"{args.env_id}: {gen.seconds_per_episode:.3f} s per generated demo, "
            f"{gen.cpu_seconds_per_episode:.3f} CPU-s ({args.policy}, {gen.control_mode}, "
            f"{gen.num_episodes} demos, {gen.seeds_tried} seeds, {args.workers} workers)"
        )
        print(f"  file: {_trajectory_size_summary(path)}")
        for target in targets:
            rep = demos.replay(
                path,
                target_control_mode=target,
                num_workers=args.workers,
                max_retry=args.max_retry,
                progress=False,
            )
            print(
                f"  -> {target:<26} {rep.num_succeeded}/{rep.num_episodes} converted "
                f"successfully ({100 * rep.success_rate:.1f} %), "
                f"{rep.seconds_per_episode:.3f} s per converted episode, "
                f"{rep.cpu_seconds_per_episode:.3f} CPU-s"
            )
    return 0


def _add_demos_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demos", help="generate demonstrations (trajectory files)")
    demos_sub = p.add_subparsers(dest="demos_command", required=True)
    fmt = HelpFormatter
    g = demos_sub.add_parser(
        "generate", help="write successful demonstrations (trajectory files)", formatter_class=fmt
    )
    g.add_argument("env_id", help="task id, e.g. PickCube-v0")
    g.add_argument("-n", "--num-episodes", type=int, default=100, help="demos to keep")
    g.add_argument("--output", "--out", required=True, help="output .h5 (its .json is written too)")
    g.add_argument(
        "-w",
        "--workers",
        type=int,
        default=1,
        help="native worker threads (with --ray: threads and CPUs of each Ray task)",
    )
    g.add_argument("--seed", type=int, default=0, help="first episode seed (then +1 each)")
    g.add_argument(
        "--max-seeds", type=int, default=None, help="give up after this many seeds (None: never)"
    )
    g.add_argument(
        "--policy",
        choices=["solution", "scripted"],
        default="solution",
        help="motion-planning solution or the scripted oracle",
    )
    g.add_argument(
        "-c",
        "--control-mode",
        default=None,
        help="control mode of the demos (None: pd_joint_pos, for soft-body envs "
        "pd_joint_delta_pos; other modes than pd_joint_pos need --policy scripted)",
    )
    g.add_argument(
        "--chunk-size",
        type=int,
        default=None,
        help="seeds per chunk; the file is committed after each (None: 4 x workers)",
    )
    g.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_ray_arguments(g, "seeds", "the chunk size")
    g.set_defaults(func=_cmd_demos_generate)
    b = demos_sub.add_parser(
        "bench", help="seconds per generated demo and per converted episode", formatter_class=fmt
    )
    b.add_argument("env_id", nargs="?", default="PickCube-v0", help="task id")
    b.add_argument("-n", "--num-episodes", type=int, default=20, help="demos to generate")
    b.add_argument("-w", "--workers", type=int, default=1, help="native worker threads")
    b.add_argument(
        "--policy", choices=["solution", "scripted"], default="solution", help="demo source"
    )
    b.add_argument("-c", "--control-mode", default=None, help="control mode of the generated demos")
    b.add_argument(
        "--max-retry",
        type=int,
        default=0,
        help="retries of a failed (or late) conversion (see docs/trajectory_format.md)",
    )
    b.add_argument(
        "--target-control-modes",
        default="pd_ee_delta_pose,pd_ee_delta_pos,pd_joint_delta_pos",
        help="comma-separated target modes",
    )
    b.set_defaults(func=_cmd_demos_bench)


def run_replay(args: argparse.Namespace) -> int:
    """Runs ``ms2 replay`` with parsed options (see :func:`add_replay_arguments`)."""
    return _cmd_replay(args)


def _cmd_replay(args: argparse.Namespace) -> int:
    from . import demos

    result = demos.replay(
        args.traj_path,
        obs_mode=args.obs_mode,
        target_control_mode=args.target_control_mode,
        use_env_states=args.use_env_states,
        save_traj=args.save_traj,
        save_video=args.save_video,
        num_workers=args.num_workers,
        max_retry=args.max_retry,
        allow_failure=args.allow_failure,
        count=args.count,
        progress=not args.quiet,
        use_first_env_state=args.use_first_env_state,
        track_hand_only=args.track_hand_only,
        discard_timeout=args.discard_timeout,
        vis=args.vis,
    )
    print(
        f"replayed {result.num_episodes} episodes: {result.num_succeeded} succeeded "
        f"({100 * result.success_rate:.1f} %) in {result.seconds:.1f} s = "
        f"{result.seconds_per_episode:.3f} s per episode"
    )
    if result.failed_episode_ids:
        kept = "kept (--allow-failure)" if args.allow_failure else "not saved"
        print(f"failed episode ids ({kept}): {result.failed_episode_ids}")
    if result.output is not None:
        print(f"wrote {result.output}")
    for video in result.videos:
        print(f"wrote {video}")
    return 0


def _add_replay_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help="replay / convert a trajectory file (ms2's or ManiSkill2's)",
        formatter_class=HelpFormatter,
    )
    add_replay_arguments(p)


def add_replay_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``ms2 replay`` (ManiSkill2's ``replay_trajectory`` names) on ``p``."""
    p.add_argument("--traj-path", required=True, help="the X.h5 to replay (with X.json)")
    p.add_argument(
        "-o",
        "--obs-mode",
        default=None,
        help="record observations of this mode (default: the file's env_kwargs obs_mode; "
        "none records none)",
    )
    p.add_argument(
        "-c",
        "--control-mode",
        "--target-control-mode",
        dest="target_control_mode",
        default=None,
        help="convert actions to this control mode (default: the recorded one)",
    )
    p.add_argument(
        "--use-env-states", action="store_true", help="restore the recorded state after every step"
    )
    p.add_argument(
        "--use-first-env-state",
        action="store_true",
        help="start from the recorded first state instead of the seed's "
        "(always on for files ManiSkill2 wrote)",
    )
    p.add_argument("--save-traj", action="store_true", help="write X.<obs_mode>.<control_mode>.h5")
    p.add_argument("--save-video", action="store_true", help="write one MP4 per episode")
    p.add_argument(
        "--vis", action="store_true", help="show each episode in a viewer window (needs a display)"
    )
    p.add_argument(
        "-w", "--num-workers", "--num-procs", type=int, default=1, help="native worker threads"
    )
    p.add_argument(
        "--max-retry",
        type=int,
        default=0,
        help="retries of a failed (or late) conversion (see docs/trajectory_format.md)",
    )
    p.add_argument(
        "--track-hand-only",
        action="store_true",
        help="convert by the source's hand path alone (no in-hand correction; ManiSkill2's way)",
    )
    p.add_argument(
        "--discard-timeout",
        action="store_true",
        help="count episodes that reach the episode limit as failed",
    )
    p.add_argument(
        "--allow-failure", action="store_true", help="also save episodes that do not succeed"
    )
    p.add_argument(
        "-n", "--count", type=int, default=None, help="replay only the first N episodes (all)"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_replay)


def _cmd_gallery(args: argparse.Namespace) -> int:
    from .gallery import render_gallery

    for path in render_gallery(args.out, args.env_ids or None, steps=args.steps, seed=args.seed):
        print(f"wrote {path}")
    return 0


def _add_gallery_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "gallery",
        help="render one picture per task (the docs/tasks.md gallery)",
        formatter_class=HelpFormatter,
    )
    p.add_argument("env_ids", nargs="*", help="tasks to render (none given: every 3D task)")
    p.add_argument("--out", default="docs/images/tasks", help="directory of <env_id>.png")
    p.add_argument("--steps", type=int, default=30, help="scripted steps before the picture")
    p.add_argument("--seed", type=int, default=0, help="episode seed")
    p.set_defaults(func=_cmd_gallery)


def build_parser() -> argparse.ArgumentParser:
    """The ``ms2`` argument parser with every subcommand."""
    from . import __version__, assets, bench, teleop
    from .evaluation import cli as evaluation_cli

    parser = argparse.ArgumentParser(prog="ms2", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"ms2 {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p_envs = sub.add_parser("envs", help="list the registered tasks")
    p_envs.set_defaults(func=_cmd_envs)
    _add_run_parser(sub)
    bench.add_parser(sub)
    assets.add_parser(sub)
    _add_demos_parser(sub)
    _add_replay_parser(sub)
    _add_gallery_parser(sub)
    teleop.add_parser(sub)
    evaluation_cli.add_parser(sub)
    _show_defaults_everywhere(parser)
    return parser


def _show_defaults_everywhere(parser: argparse.ArgumentParser) -> None:
    """Gives every (sub)command's help the :class:`HelpFormatter`, so each option shows its
    default whichever module added it."""
    parser.formatter_class = HelpFormatter
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                _show_defaults_everywhere(sub)


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the ``ms2`` command line with ``argv`` (default: ``sys.argv[1:]``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    from . import interrupts

    interrupts.install()
    try:
        code = int(args.func(args))
        interrupts.check()  # an interrupt that something swallowed still ends in 130
        return code
    except KeyboardInterrupt:
        # Trajectory files are committed chunk by chunk: what is on disk is complete.
        print(f"ms2 {args.command}: interrupted", file=sys.stderr)
        return 130
    except (ValueError, TypeError, RuntimeError, OSError, OverflowError) as err:
        # OSError: unwritable or missing paths (PermissionError, NotADirectoryError, ...).
        print(f"ms2 {args.command}: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = ["main"]
