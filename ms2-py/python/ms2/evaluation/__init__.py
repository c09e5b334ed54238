"""Evaluating solutions as ManiSkill2's evaluation does (``ms2 evaluate``).

A solution is a Python file defining ``UserPolicy``, a subclass of
:class:`ms2.evaluation.solution.BasePolicy`; :func:`run_evaluation` plays it on a task's
episodes (a ManiSkill2 episode configuration, or seeded episodes; held-out models where the
task has them) and writes ManiSkill2's ``episode_results.json`` and ``average_metrics.json``
plus ms2's ``results.json``. Failures of the solution in an episode (exceptions, NaN or
malformed actions, per-step timeouts) are recorded with their reason and the evaluation goes
on. :func:`write_leaderboard` renders several results into one HTML table. See
``docs/evaluation.md``.

Modules: :mod:`.solution` (the policy interface), :mod:`.config` (episodes),
:mod:`.loader` (importing a solution file), :mod:`.guard` (time limits, action checks),
:mod:`.evaluator`, :mod:`.results` (files), :mod:`.leaderboard`, :mod:`.cli`.
"""

from __future__ import annotations

from .config import ConfigError, EpisodeConfig, EvaluationConfig, load_config, seeded_config
from .evaluator import Evaluator, run_evaluation
from .guard import FAILURE_KINDS, PolicyFailure
from .leaderboard import write_leaderboard
from .loader import SolutionError, load_solution
from .results import EpisodeResult
from .solution import BasePolicy, RandomPolicy

__all__ = [
    "FAILURE_KINDS",
    "BasePolicy",
    "ConfigError",
    "EpisodeConfig",
    "EpisodeResult",
    "EvaluationConfig",
    "Evaluator",
    "PolicyFailure",
    "RandomPolicy",
    "SolutionError",
    "load_config",
    "load_solution",
    "run_evaluation",
    "seeded_config",
    "write_leaderboard",
]
