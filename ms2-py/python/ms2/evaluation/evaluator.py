"""The evaluator: runs a solution's policy on the episodes of a configuration and records how
each went (ManiSkill2's ``Evaluator``, with failures contained per episode).

:class:`Evaluator` makes the env in the modes the policy class asks for, builds the policy, and
plays episodes: ``env.reset(**reset_kwargs)``, ``policy.reset(obs)``, then ``policy.act(obs)`` /
``env.step(action)`` until the episode terminates or is truncated. An exception in ``reset`` or
``act``, an action that is not a finite real array of the action space's shape, a call that
overruns the per-step time limit or an env that refuses to reset or step ends that episode as
*failed* (:mod:`ms2.evaluation.guard` names the kinds) and the next episode starts. Actions
outside the action space's bounds are passed on unchanged, as ManiSkill2's evaluator does (the
normalized controllers clip them).

:func:`run_evaluation` is the whole ``ms2 evaluate`` run: load the solution, evaluate, write
the results (:mod:`ms2.evaluation.results`). With ``ray=RayOptions(...)`` its episodes run in
chunks as Ray tasks (:func:`evaluate_chunk` on each, :mod:`ms2.distributed`), merged back in
episode order into the same files.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym

from ..distributed import RayOptions, ray_chunks
from .config import EpisodeConfig, EvaluationConfig, load_config, model_split, seeded_config
from .guard import PolicyCaller, PolicyFailure, check_action, describe_exception
from .loader import SolutionError, load_solution
from .results import EpisodeResult, extract_scalars, summarize, write_results

#: Longest episode the evaluator plays (ManiSkill2's guard against an env without time limit).
MAX_EPISODE_STEPS = 1000

#: Default per-call time limit of ``act`` / ``reset`` in seconds.
DEFAULT_STEP_TIME_LIMIT = 10.0


def check_env_id(env_id: str) -> str:
    """``env_id`` if ms2 registers it, else ``ValueError`` listing the registered ids."""
    import ms2

    ids = ms2.env_ids()
    if env_id not in ids:
        raise ValueError(f"unknown env id {env_id!r}; valid ids: {ids}")
    return env_id


def _check_video_support() -> None:
    """``RuntimeError`` naming the ``video`` extra if imageio / imageio-ffmpeg are missing (checked
    before any episode runs, rather than failing at the first video)."""
    try:
        import imageio.v2  # noqa: F401
        import imageio_ffmpeg  # noqa: F401
    except ImportError as err:
        raise RuntimeError(
            f"recording videos (record_dir / --record-dir) needs imageio and imageio-ffmpeg "
            f"({err}): pip install 'ms2[video]'"
        ) from err


def _episode_identity(env: Any) -> tuple[int | None, str | None]:
    """The current episode's seed and asset model id (``None`` where there is none)."""
    try:
        seed: int | None = int(env.episode_seed)
    except (AttributeError, ValueError, TypeError, RuntimeError):
        seed = None
    try:
        model_id: str | None = str(env.model_id)
    except (AttributeError, ValueError, RuntimeError):
        model_id = None
    return seed, model_id


class Evaluator:
    """Evaluates ``policy_cls`` (a ``UserPolicy`` class) on episodes of ``env_id``.

    Args:
        env_id: the task.
        policy_cls: the solution's policy class (:class:`ms2.evaluation.solution.BasePolicy`'s
            interface).
        env_kwargs: further ``gymnasium.make`` keywords (a configuration's ``env_kwargs``).
        split: the model set of tasks that have train and test models (``"test"``: the
            held-out ones; see :data:`ms2.evaluation.config.MODEL_SPLIT_VARIABLES`).
        step_time_limit: seconds each ``act`` / ``reset`` call may take (``None``: no limit,
            calls run in this thread).
        record_dir: write each episode's video (``episode_<i>.mp4``, i counting the evaluated
            episodes from 0) and trajectory (``trajectory.h5`` + ``.json``) there.

    Raises :class:`SolutionError` if the policy class's modes are refused or its constructor
    raises: then no episode can be evaluated.
    """

    def __init__(
        self,
        env_id: str,
        policy_cls: type,
        *,
        env_kwargs: dict[str, Any] | None = None,
        split: str = "test",
        step_time_limit: float | None = DEFAULT_STEP_TIME_LIMIT,
        record_dir: str | os.PathLike[str] | None = None,
    ) -> None:
        self.env_id = check_env_id(env_id)
        self.policy_cls = policy_cls
        self.caller = PolicyCaller(step_time_limit)
        self.obs_mode = self._ask_mode("get_obs_mode")
        self.control_mode = self._ask_mode("get_control_mode")
        if record_dir is not None:
            _check_video_support()
        render_mode = "rgb_array" if record_dir is not None else None
        make_kwargs = dict(env_kwargs or {})
        try:
            with model_split(env_id, split) as used_split:
                env = gym.make(
                    env_id,
                    obs_mode=self.obs_mode,
                    control_mode=self.control_mode,
                    render_mode=render_mode,
                    **make_kwargs,
                )
        except (ValueError, TypeError) as err:
            raise SolutionError(
                f"cannot make {env_id} with obs_mode={self.obs_mode!r} and control_mode="
                f"{self.control_mode!r} (from {policy_cls.__name__}.get_obs_mode / "
                f"get_control_mode) and env_kwargs {make_kwargs}: {err}"
            ) from err
        self.split = used_split
        self.control_mode = env.unwrapped.control_mode  # the task's default filled in
        if record_dir is not None:
            from ..recording import RecordEpisode

            env = RecordEpisode(env, record_dir, save_on_reset=False, clean_on_close=False)
        self.env = env
        self.policy: Any = None
        try:
            self.policy = self._new_policy()
        except PolicyFailure as failure:
            self.env.close()
            raise SolutionError(failure.reason) from failure

    def _ask_mode(self, method: str) -> str | None:
        """The policy class's answer to ``method(env_id)``: a string or ``None``."""
        what = f"{self.policy_cls.__name__}.{method}({self.env_id!r})"
        try:
            mode = getattr(self.policy_cls, method)(self.env_id)
        except (Exception, SystemExit) as err:
            raise SolutionError(f"{what} raised {describe_exception(err)}") from err
        if mode is not None and not isinstance(mode, str):
            raise SolutionError(f"{what} returned {mode!r}; expected a mode name (str) or None")
        return mode

    def _new_policy(self) -> Any:
        """A fresh policy object (``PolicyFailure`` if its constructor raises)."""
        env = self.env
        what = f"{self.policy_cls.__name__}({self.env_id!r}, observation_space, action_space)"
        try:
            return self.policy_cls(self.env_id, env.observation_space, env.action_space)
        except (Exception, SystemExit) as err:
            raise PolicyFailure("exception", f"{what} raised {describe_exception(err)}") from err

    def evaluate_episode(self, episode: EpisodeConfig) -> EpisodeResult:
        """Plays one episode; a failure of the solution ends it as a failed episode."""
        started = time.perf_counter()
        env = self.env
        info: dict[str, Any] = {}
        steps = 0
        failure: PolicyFailure | None = None
        abandoned_before = self.caller.abandoned
        was_reset = False
        try:
            try:
                obs, info = env.reset(**episode.reset_kwargs)
            except (ValueError, TypeError, RuntimeError) as err:
                raise PolicyFailure(
                    "env_error", f"env.reset(**{episode.reset_kwargs}) failed: {err}"
                ) from err
            was_reset = True
            if self.policy is None:  # the previous one was abandoned mid-call
                self.policy = self._new_policy()
            self.caller.call("reset(obs)", self.policy.reset, obs)
            while True:
                action = self.caller.call("act(obs)", self.policy.act, obs)
                action = check_action(action, env.action_space)
                try:
                    obs, _reward, terminated, truncated, info = env.step(action)
                except (ValueError, RuntimeError) as err:
                    raise PolicyFailure("env_error", f"env.step failed: {err}") from err
                steps += 1
                if terminated or truncated:
                    break
                if steps >= MAX_EPISODE_STEPS:
                    raise PolicyFailure(
                        "env_error",
                        f"the episode did not end within {MAX_EPISODE_STEPS} steps (is "
                        "env_kwargs.max_episode_steps larger?)",
                    )
        except PolicyFailure as err:
            failure = err
        if self.caller.abandoned > abandoned_before:
            self.policy = None  # still running in an abandoned thread: build a new one
        metrics = extract_scalars(info, blacklist=("TimeLimit.truncated",))
        metrics["elapsed_steps"] = float(metrics.get("elapsed_steps", steps))
        if failure is not None:
            metrics["success"] = 0.0
        metrics["failed"] = float(failure is not None)
        video = None
        if was_reset and hasattr(env, "flush_video"):
            path = env.flush_video()
            env.flush_trajectory()
            video = str(path) if path is not None else None
        if was_reset:
            seed, model_id = _episode_identity(env.unwrapped)
        else:  # the env still holds the previous episode
            seed, model_id = episode.reset_kwargs.get("seed"), None
        return EpisodeResult(
            episode_id=episode.episode_id,
            seed=seed,
            model_id=model_id,
            metrics=metrics,
            seconds=time.perf_counter() - started,
            failure_kind=None if failure is None else failure.kind,
            failure_reason=None if failure is None else failure.reason,
            failure_step=None if failure is None else steps,
            video=video,
        )

    def evaluate(
        self,
        episodes: Sequence[EpisodeConfig],
        callback: Callable[[int, EpisodeResult], None] | None = None,
    ) -> list[EpisodeResult]:
        """Plays ``episodes`` in order; ``callback(done, result)`` after each."""
        results = []
        for i, episode in enumerate(episodes):
            results.append(self.evaluate_episode(episode))
            if callback is not None:
                callback(i + 1, results[-1])
        return results

    def close(self) -> None:
        """Closes the env (writing the recording's files) and the policy's worker thread."""
        self.caller.close()
        self.env.close()


#: Episodes per Ray task by default.
DEFAULT_RAY_TASK_SIZE = 4


def evaluate_chunk(
    episodes: Sequence[EpisodeConfig],
    env_id: str,
    solution_file: str,
    env_kwargs: dict[str, Any],
    split: str,
    step_time_limit: float | None,
) -> list[tuple[EpisodeResult, int]]:
    """Evaluates the ``UserPolicy`` of ``solution_file`` on ``episodes`` in a fresh
    :class:`Evaluator`: what one Ray task of ``ms2 evaluate --ray`` runs. Returns each
    episode's result with the number of timed-out calls abandoned during it."""
    evaluator = Evaluator(
        env_id,
        load_solution(solution_file),
        env_kwargs=env_kwargs,
        split=split,
        step_time_limit=step_time_limit,
    )
    out = []
    try:
        for episode in episodes:
            before = evaluator.caller.abandoned
            result = evaluator.evaluate_episode(episode)
            out.append((result, evaluator.caller.abandoned - before))
    finally:
        evaluator.close()
    return out


def run_evaluation(
    env_id: str,
    solution: str | os.PathLike[str] | type,
    output_dir: str | os.PathLike[str],
    *,
    config: str | os.PathLike[str] | EvaluationConfig | None = None,
    num_episodes: int | None = None,
    first_seed: int = 0,
    split: str = "test",
    step_time_limit: float | None = DEFAULT_STEP_TIME_LIMIT,
    record_dir: str | os.PathLike[str] | None = None,
    name: str | None = None,
    progress: bool = False,
    ray: RayOptions | None = None,
) -> dict[str, Any]:
    """``ms2 evaluate``: evaluates the solution file (or policy class) ``solution`` on
    ``env_id`` and writes the results into ``output_dir``; returns ``results.json``'s content.

    Episodes: the configuration file ``config`` (its first ``num_episodes`` if given), else
    ``num_episodes`` (default 10) seeded episodes from ``first_seed``. ``record_dir="@"`` records
    into ``output_dir`` (ManiSkill2's convention). ``name`` labels the solution in the results
    (default: the file's name without ``.py``).

    Raises ``ValueError`` (:class:`SolutionError`, :class:`~ms2.evaluation.config.ConfigError`)
    for an unknown env id, a bad configuration or a solution that cannot run at all; failures
    of single episodes are recorded instead.

    ``ray``: run the episodes as Ray tasks of ``ray.task_size`` episodes (default
    :data:`DEFAULT_RAY_TASK_SIZE`) on the cluster ``ray.address``; each task loads
    ``solution`` (a file path, which must exist at the same path on every node) in its own
    :class:`Evaluator`. The results are those of a local run but for the timings. Videos
    (``record_dir``) are not recorded on Ray.
    """
    check_env_id(env_id)
    if num_episodes is not None and (
        isinstance(num_episodes, bool) or not isinstance(num_episodes, int) or num_episodes < 1
    ):
        raise ValueError(f"num_episodes must be a positive int, got {num_episodes!r}")
    if isinstance(config, EvaluationConfig):
        cfg = config
    elif config is not None:
        cfg = load_config(config, env_id)
    else:
        cfg = seeded_config(env_id, num_episodes or 10, first_seed)
    episodes = cfg.episodes[:num_episodes] if num_episodes is not None else cfg.episodes
    if isinstance(solution, type):
        policy_cls, solution_file = solution, None
        label = name or solution.__name__
    else:
        policy_cls = load_solution(solution)
        solution_file = str(Path(solution).resolve())
        label = name or Path(solution).stem
    if record_dir is not None and str(record_dir) == "@":
        record_dir = output_dir
    if ray is not None and solution_file is None:
        raise ValueError(
            f"evaluating on Ray needs a solution file path (each Ray task loads it), not the "
            f"class {label}"
        )
    if ray is not None and record_dir is not None:
        raise ValueError(f"evaluating on Ray records no videos; drop record_dir ({record_dir!r})")
    started = time.perf_counter()
    evaluator = Evaluator(
        env_id,
        policy_cls,
        env_kwargs=cfg.env_kwargs,
        split=split,
        step_time_limit=step_time_limit,
        record_dir=record_dir,
    )
    bar = _ProgressBar(len(episodes), f"evaluate {label} on {env_id}", progress)
    abandoned = 0
    try:
        if ray is None:
            results = evaluator.evaluate(episodes, callback=bar)
        else:  # the evaluator here checked the solution and gives the header's modes
            args = (env_id, solution_file, cfg.env_kwargs, split, step_time_limit)
            results = []
            with ray_chunks(episodes, evaluate_chunk, args, ray, DEFAULT_RAY_TASK_SIZE) as stream:
                for result, abandoned_in_episode in stream:
                    results.append(result)
                    abandoned += abandoned_in_episode
                    bar(len(results), result)
    finally:
        bar.close()
        evaluator.close()
    abandoned += evaluator.caller.abandoned
    import ms2

    header = {
        "env_id": env_id,
        "solution": label,
        "solution_file": solution_file,
        "obs_mode": evaluator.obs_mode,
        "control_mode": evaluator.control_mode,
        "model_split": evaluator.split,
        "env_kwargs": cfg.env_kwargs,
        "step_time_limit": step_time_limit,
        "abandoned_calls": abandoned,
        "seconds": round(time.perf_counter() - started, 3),
        "ms2_version": ms2.__version__,
    }
    write_results(output_dir, results, header)
    return summarize(results, header)


class _ProgressBar:
    """A tqdm bar over the episodes showing successes and failures (a no-op when disabled)."""

    def __init__(self, total: int, desc: str, enabled: bool) -> None:
        self._bar = None
        self._successes = self._failed = 0
        if enabled:
            from tqdm.auto import tqdm

            self._bar = tqdm(total=total, desc=desc, unit="ep", dynamic_ncols=True)

    def __call__(self, done: int, result: EpisodeResult) -> None:
        self._successes += result.success
        self._failed += result.failed
        if self._bar is not None:
            self._bar.update(1)
            self._bar.set_postfix(success=self._successes, failed=self._failed)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


__all__ = [
    "DEFAULT_RAY_TASK_SIZE",
    "DEFAULT_STEP_TIME_LIMIT",
    "MAX_EPISODE_STEPS",
    "Evaluator",
    "evaluate_chunk",
    "run_evaluation",
]
