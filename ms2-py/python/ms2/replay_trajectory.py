"""``ms2 replay`` as a module, with the entry points of ManiSkill2's
``mani_skill2.trajectory.replay_trajectory``: ``main(parse_args([...]))``."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from .cli import HelpFormatter, add_replay_arguments, run_replay


def parse_args(args: Sequence[str] | None = None) -> argparse.Namespace:
    """Parses ``ms2 replay``'s options (``--traj-path``, ``-o``, ``-c``, ``--save-traj``, ...)
    from ``args`` (default: ``sys.argv[1:]``)."""
    parser = argparse.ArgumentParser(prog="ms2 replay", formatter_class=HelpFormatter)
    add_replay_arguments(parser)
    parser.set_defaults(quiet=False)
    return parser.parse_args(args)


def main(args: argparse.Namespace) -> int:
    """Replays / converts as ``ms2 replay`` does; returns 0."""
    return run_replay(args)


__all__ = ["main", "parse_args"]
