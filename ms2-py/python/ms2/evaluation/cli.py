"""``ms2 evaluate`` and ``ms2 leaderboard`` on the command line.

``ms2 evaluate --env-id PickCube-v0 --solution user_solution.py -o results/`` evaluates a solution
(ManiSkill2's ``run_evaluation`` options: ``-o`` is the output directory here, as there);
``ms2 leaderboard results_a/ results_b/ -o board.html`` renders several runs into one table.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..distributed import add_ray_arguments, ray_options_from_args
from .config import MODEL_SPLITS
from .evaluator import DEFAULT_RAY_TASK_SIZE, DEFAULT_STEP_TIME_LIMIT, run_evaluation
from .leaderboard import write_leaderboard
from .results import ERROR_LOG_FILE, write_text_atomic


def _positive_seconds(text: str) -> float | None:
    """``--step-time-limit``'s value: seconds > 0, or 0 / ``none`` for no limit."""
    if text.strip().lower() in ("0", "none"):
        return None
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected seconds (a number) or 'none', got {text!r}"
        ) from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}")
    return value


def _cmd_evaluate(args: argparse.Namespace) -> int:
    try:
        summary = run_evaluation(
            args.env_id,
            args.solution,
            args.output_dir,
            config=args.config,
            num_episodes=args.num_episodes,
            first_seed=args.seed,
            split=args.split,
            step_time_limit=args.step_time_limit,
            record_dir=args.record_dir,
            name=args.name,
            progress=not args.quiet,
            ray=ray_options_from_args(args),
        )
    except (ValueError, TypeError, RuntimeError, OSError) as err:
        # As ManiSkill2's evaluation: the reason also goes to <output>/error.log.
        try:
            write_text_atomic(Path(args.output_dir) / ERROR_LOG_FILE, f"{err}\n")
        except OSError:
            pass
        raise
    _print_summary(summary, Path(args.output_dir))
    return 0


def _print_summary(summary: dict[str, Any], output_dir: Path) -> None:
    n = summary["num_episodes"]
    print(
        f"{summary['env_id']} [{summary['obs_mode']}, {summary['control_mode']}"
        + (f", {summary['model_split']} models" if summary["model_split"] else "")
        + f"] {summary['solution']}: success rate {summary['num_successes']}/{n} = "
        f"{100.0 * summary['success_rate']:.1f} %, mean episode length "
        f"{summary['mean_episode_length']:.1f}, {summary['num_failed']} failed episode(s)"
    )
    for episode in summary["episodes"]:
        failure = episode["failure"]
        if failure is not None:
            print(
                f"  episode {episode['episode_id']} (seed {episode['seed']}): {failure['kind']} "
                f"at step {failure['step']}: {failure['reason']}"
            )
    if summary["abandoned_calls"]:
        print(
            f"  {summary['abandoned_calls']} timed-out call(s) were abandoned and may still be "
            "running in background threads"
        )
    print(f"results: {output_dir / 'results.json'} (+ episode_results.json, average_metrics.json)")


def _cmd_leaderboard(args: argparse.Namespace) -> int:
    path = write_leaderboard(args.results, args.output, title=args.title)
    print(f"wrote {path} ({len(args.results)} result set(s))")
    return 0


def add_parser(sub: Any) -> None:
    """Adds ``ms2 evaluate`` and ``ms2 leaderboard`` to the command line."""
    p = sub.add_parser(
        "evaluate",
        help="evaluate a solution (ManiSkill2's UserPolicy) on a task's test episodes",
        description="Evaluates the UserPolicy of a solution file on episodes of a task and "
        "writes per-episode and averaged results (ManiSkill2's format) plus results.json. A "
        "solution that raises, returns a NaN or malformed action, or exceeds the per-step time "
        "limit fails that episode; the evaluation goes on.",
    )
    p.add_argument("-e", "--env-id", required=True, help="task id, e.g. PickCube-v0")
    p.add_argument(
        "--solution", required=True, help="Python file defining UserPolicy (user_solution.py)"
    )
    p.add_argument("-o", "--output-dir", required=True, help="directory for the results (created)")
    p.add_argument(
        "--config",
        "--config-file",
        dest="config",
        default=None,
        help="episodes json (ManiSkill2's layout); default: seeded episodes",
    )
    p.add_argument(
        "-n",
        "--num-episodes",
        type=int,
        default=None,
        help="episodes to run: the config's first N, or N seeded episodes (default 10)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the first seeded episode")
    p.add_argument(
        "--split",
        choices=MODEL_SPLITS,
        default="test",
        help="model set of tasks with train/test models (TurnFaucet, OpenCabinet*, PushChair, "
        "MoveBucket); sets their MS2_*_MODELS variable",
    )
    p.add_argument(
        "--step-time-limit",
        type=_positive_seconds,
        default=DEFAULT_STEP_TIME_LIMIT,
        metavar="SECONDS",
        help="wall time each act()/reset() call may take; 0 or 'none': no limit",
    )
    p.add_argument(
        "--record-dir",
        default=None,
        help="save each episode's video and trajectory there ('@': the output directory)",
    )
    p.add_argument("--name", default=None, help="solution name in the results (default: file stem)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_ray_arguments(p, "episodes", str(DEFAULT_RAY_TASK_SIZE))
    p.set_defaults(func=_cmd_evaluate)

    lb = sub.add_parser(
        "leaderboard",
        help="render several `ms2 evaluate` results into one static HTML table",
    )
    lb.add_argument("results", nargs="+", help="result directories (or results.json files)")
    lb.add_argument("-o", "--output", required=True, help="the HTML file to write")
    lb.add_argument("--title", default="ms2 leaderboard", help="page title")
    lb.set_defaults(func=_cmd_leaderboard)


__all__ = ["add_parser"]
