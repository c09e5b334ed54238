"""Demonstrations: generating trajectory files and replaying / converting them.

* :func:`generate` — runs a demonstration source (the motion-planning solution, or the scripted
  oracle) over seeds ``seed, seed + 1, ...`` on native worker threads, keeps the successful
  episodes and writes them to ``X.h5`` + ``X.json`` (:mod:`ms2.trajectory`), committing after
  every chunk of seeds so an interrupted run leaves a valid file of the episodes finished so far.
* :func:`replay` — replays the episodes of a trajectory file from their seeds, optionally
  restoring the recorded states, recording observations of any obs mode, converting the actions
  closed-loop to another control mode (ManiSkill2 paper, Sec. 2.2), and writing the result to
  ``X.<obs_mode>.<control_mode>.h5``.

Soft-body envs (those with an ``mpm_freq``: Excavate-v0, Fill-v0) are written in ManiSkill2's
soft-body layout: each episode keeps only ``env_init_state`` (the state after reset), and
replays restore it after ``reset(seed)`` and step the actions (the simulation is
deterministic); conversions re-simulate the source alongside.

The simulation runs in Rust (``ms2._native.solve_episodes`` / ``scripted_episodes`` /
``replay_episodes``) with the GIL released, on a pool of ``num_workers`` threads. With
``ray=RayOptions(...)`` :func:`generate` runs its chunks of seeds as Ray tasks instead
(:mod:`ms2.distributed`, docs/ray.md) and writes the same file.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import _native, interrupts
from .distributed import RayOptions, ray_chunks
from .trajectory import (
    MAX_SEED,
    TrajectoryFileError,
    TrajectoryWriter,
    check_output_path,
    is_soft_episode,
    open_trajectory,
)

#: Control mode the demonstration sources produce.
SOURCE_CONTROL_MODE = "pd_joint_pos"
#: Control mode of scripted soft-body demonstrations (the soft envs' default): its actions are
#: rate-limited, so their conversion to end-effector modes follows the source's path (Fill-v0:
#: 20/20 to ``pd_ee_delta_pose`` against 16/20 from ``pd_joint_pos`` sources).
SOFT_SOURCE_CONTROL_MODE = "pd_joint_delta_pos"
#: Demonstration sources of :func:`generate`.
POLICIES = ("solution", "scripted")
#: Most native worker threads a call starts (also capped at the seeds or episodes to run).
MAX_WORKERS = 256
#: Most demonstrations one :func:`generate` call writes.
MAX_EPISODES = 10_000_000


def _check_int(name: str, value: Any, low: int, high: int | None) -> None:
    """Refuses a non-int (``bool`` included: ``TypeError``) or an int outside ``[low, high]``
    (``ValueError``), naming ``name`` and the range."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{name} must be an int, got {type(value).__name__} {value!r}")
    if value < low or (high is not None and value > high):
        bound = f"in [{low}, {high}]" if high is not None else f">= {low}"
        raise ValueError(f"{name} must be {bound}, got {value}")


def _progress(total: int, desc: str, enabled: bool) -> Any:
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit="ep", disable=not enabled, dynamic_ncols=True)


def _chunks(items: Sequence[Any], size: int) -> Iterator[Sequence[Any]]:
    for start in range(0, len(items), size):
        yield items[start : start + size]


def run_seed_chunk(
    seeds: Sequence[int], policy: str, env_id: str, env_kwargs: dict[str, Any], num_workers: int
) -> list[dict[str, Any]]:
    """The episodes of ``seeds`` (in their order) by demonstration source ``policy`` on
    ``num_workers`` native threads: what :func:`generate` runs per chunk, locally or as a Ray
    task (a pure function of its arguments, so a retried task gives the same episodes)."""
    run = _native.solve_episodes if policy == "solution" else _native.scripted_episodes
    return run(env_id, list(seeds), env_kwargs, num_workers)


def _succeeded(episode: dict[str, Any]) -> bool:
    """Whether an episode dict succeeds at its last step."""
    success = episode["success"]
    return len(success) > 0 and bool(success[-1])


class _PerEpisodeCost:
    """Wall-clock and CPU seconds per episode of a result with ``num_episodes``, ``seconds`` and
    ``cpu_seconds`` (kept episodes for :func:`generate`, replayed ones for :func:`replay`)."""

    num_episodes: int
    seconds: float
    cpu_seconds: float

    @property
    def seconds_per_episode(self) -> float:
        """Wall-clock seconds per episode."""
        return self.seconds / max(self.num_episodes, 1)

    @property
    def cpu_seconds_per_episode(self) -> float:
        """CPU seconds (all threads of the process) per episode."""
        return self.cpu_seconds / max(self.num_episodes, 1)


@dataclass
class GenerateResult(_PerEpisodeCost):
    """What :func:`generate` did."""

    path: Path
    num_episodes: int
    seeds_tried: int
    planner_errors: int
    seconds: float
    failed_seeds: list[int] = field(default_factory=list)
    cpu_seconds: float = 0.0
    control_mode: str = SOURCE_CONTROL_MODE
    #: Ray runs: chunks the driver submitted again after their task was lost.
    resubmitted_chunks: int = 0


def generate(
    env_id: str,
    num_episodes: int,
    output: str | os.PathLike[str],
    num_workers: int = 1,
    seed: int = 0,
    max_seeds: int | None = None,
    policy: str = "solution",
    chunk_size: int | None = None,
    progress: bool = True,
    control_mode: str | None = None,
    ray: RayOptions | None = None,
) -> GenerateResult:
    """Writes ``num_episodes`` successful demonstrations of ``env_id`` to ``output`` (``.h5``;
    the ``.json`` is written next to it), in ``pd_joint_pos`` (the motion-planning solutions'
    mode) or, with ``policy="scripted"``, in ``control_mode`` (any position-based mode the
    scripted oracle drives; default ``pd_joint_pos``, but ``SOFT_SOURCE_CONTROL_MODE`` for
    soft-body envs, whose rate-limited demos convert closed-loop to other modes better).
    Soft-body envs are written in the soft-body layout (``env_init_state``) with their
    ``mpm_freq`` in ``env_kwargs``.

    Seeds ``seed, seed + 1, ...`` are tried in chunks of ``chunk_size`` (default
    ``4 * num_workers``) until ``num_episodes`` succeed or ``max_seeds`` (default
    ``4 * num_episodes + 20``) were tried; the file is committed after each chunk. ``policy`` is
    ``"solution"`` (the motion-planning solution, see ``ms2._native.solution_env_ids()``) or
    ``"scripted"`` (the scripted oracle). Raises ``ValueError`` for bad arguments or an env
    without that policy; ``RuntimeError`` when fewer episodes than asked succeeded within
    ``max_seeds`` (the file then holds those that did).

    ``ray``: run the seeds as Ray tasks of ``ray.task_size`` seeds (default ``chunk_size``)
    with ``ray.num_cpus`` threads each, on the cluster ``ray.address``. The driver takes the
    episodes back in seed order and commits the file exactly as a local run with the same
    ``num_workers`` and ``chunk_size`` (seeds beyond those a local run would try are run
    ahead on idle workers and discarded), so the files are byte-identical to that run's.
    """
    _check_int("num_episodes", num_episodes, 1, MAX_EPISODES)
    _check_int("num_workers", num_workers, 1, None)
    _check_int("seed", seed, 0, MAX_SEED)
    if max_seeds is not None:
        _check_int("max_seeds", max_seeds, 1, None)
    if chunk_size is not None:
        _check_int("chunk_size", chunk_size, 1, None)
    check_output_path(Path(output))
    if policy not in POLICIES:
        raise ValueError(f"unknown policy {policy!r}; valid: {list(POLICIES)}")
    if policy == "solution" and env_id not in _native.solution_env_ids():
        raise ValueError(
            f"no motion-planning solution for {env_id!r}; envs with one: "
            f"{sorted(_native.solution_env_ids())} (or use policy='scripted')"
        )
    if control_mode is None:
        soft = "mpm_freq" in _native.recorded_env_kwargs(env_id, {"obs_mode": "state"})
        control_mode = SOFT_SOURCE_CONTROL_MODE if soft else SOURCE_CONTROL_MODE
    if policy == "solution" and control_mode != SOURCE_CONTROL_MODE:
        raise ValueError(
            f"the motion-planning solutions act in {SOURCE_CONTROL_MODE!r}, not {control_mode!r} "
            "(convert with ms2 replay, or use policy='scripted')"
        )
    max_seeds = 4 * num_episodes + 20 if max_seeds is None else max_seeds
    if seed + max_seeds - 1 > MAX_SEED:
        raise ValueError(
            f"seeds {seed}..{seed + max_seeds - 1} would pass the largest seed {MAX_SEED} "
            f"(2**64 - 1); use a seed of at most {MAX_SEED - max_seeds + 1}"
        )
    # No more threads than seeds to try, nor than MAX_WORKERS.
    num_workers = min(num_workers, max_seeds, MAX_WORKERS)
    chunk_size = chunk_size or 4 * num_workers
    env_kwargs = {"obs_mode": "state", "control_mode": control_mode}
    recorded = dict(_native.recorded_env_kwargs(env_id, env_kwargs))
    # No observations are stored: the file says so, as ManiSkill2's demonstrations do (replays
    # record the obs mode of env_kwargs unless told another).
    recorded["obs_mode"] = "none"
    env_info = {
        "env_id": env_id,
        "max_episode_steps": int(recorded.pop("max_episode_steps")),
        "env_kwargs": recorded,
    }
    started, cpu_started = time.perf_counter(), time.process_time()
    result = GenerateResult(Path(output), 0, 0, 0, 0.0, control_mode=control_mode)
    if ray is None:

        def take(seeds: list[int]) -> list[dict[str, Any]]:
            return run_seed_chunk(seeds, policy, env_id, env_kwargs, num_workers)

        stream = None
    else:
        stream = ray_chunks(
            range(seed, seed + max_seeds),
            run_seed_chunk,
            (policy, env_id, env_kwargs, ray.num_cpus),
            ray,
            chunk_size,
        )

        def take(seeds: list[int]) -> list[dict[str, Any]]:
            return stream.take(len(seeds))  # the stream's next seeds: these (checked below)

    with (
        TrajectoryWriter(output, env_info) as writer,
        _progress(num_episodes, f"{env_id} demos", progress) as bar,
        stream if stream is not None else contextlib.nullcontext(),
    ):
        writer.commit()  # a valid (empty) file from the start
        next_seed = seed
        while result.num_episodes < num_episodes and result.seeds_tried < max_seeds:
            interrupts.check()
            # Whole chunks while many episodes remain; near the end, no more seeds than needed.
            remaining = num_episodes - result.num_episodes
            count = min(chunk_size, max(remaining, num_workers), max_seeds - result.seeds_tried)
            seeds = list(range(next_seed, next_seed + count))
            next_seed += count
            result.seeds_tried += count
            episodes = take(seeds)
            got = [int(episode["episode_seed"]) for episode in episodes]
            if got != seeds:
                raise RuntimeError(f"episodes of seeds {got} came back for seeds {seeds}")
            for episode in episodes:
                if "error" in episode:
                    result.planner_errors += 1
                    result.failed_seeds.append(int(episode["episode_seed"]))
                elif _succeeded(episode):
                    if result.num_episodes == num_episodes:
                        continue  # the chunk found more than needed
                    writer.append(episode)
                    result.num_episodes += 1
                    bar.update(1)
                else:
                    result.failed_seeds.append(int(episode["episode_seed"]))
            writer.commit()
            bar.set_postfix(seeds=result.seeds_tried)
    result.seconds = time.perf_counter() - started
    result.cpu_seconds = time.process_time() - cpu_started
    result.resubmitted_chunks = stream.resubmitted if stream is not None else 0
    if result.num_episodes < num_episodes:
        raise RuntimeError(
            f"only {result.num_episodes} of {num_episodes} {env_id} episodes succeeded within "
            f"{result.seeds_tried} seeds ({result.path} holds them); raise max_seeds"
        )
    return result


def replay_output_path(
    traj_path: str | os.PathLike[str], obs_mode: str | None, control_mode: str
) -> Path:
    """ManiSkill2's name of a replayed copy: ``X.<obs_mode>.<control_mode>.h5`` (``none`` when
    no observations are recorded)."""
    path = Path(traj_path)
    return path.with_name(f"{path.stem}.{obs_mode or 'none'}.{control_mode}.h5")


@dataclass
class ReplayResult(_PerEpisodeCost):
    """What :func:`replay` did."""

    num_episodes: int
    num_succeeded: int
    seconds: float
    output: Path | None
    attempts: int
    failed_episode_ids: list[int] = field(default_factory=list)
    videos: list[Path] = field(default_factory=list)
    cpu_seconds: float = 0.0

    @property
    def success_rate(self) -> float:
        return self.num_succeeded / max(self.num_episodes, 1)


def _write_video(env_id: str, env_kwargs: dict[str, Any], episode: dict[str, Any], path: Path):
    """Renders ``episode`` (the human view) into an MP4 at ``path``: each recorded state of a
    rigid-body episode; a soft-body episode is re-simulated (its ``env_init_state`` restored
    after the reset, then its actions stepped), rendering as it goes."""
    from .recording import write_video

    env = _native.NativeEnv(
        env_id,
        obs_mode="state",
        control_mode=episode["control_mode"],
        render_mode="rgb_array",
        sim_freq=float(env_kwargs.get("sim_freq", 500.0)),
        control_freq=float(env_kwargs.get("control_freq", 20.0)),
        mpm_freq=env_kwargs.get("mpm_freq"),
    )
    env.reset(seed=int(episode["episode_seed"]))
    fps = float(env_kwargs.get("control_freq", 20.0))
    if is_soft_episode(episode):
        env.set_state(episode["env_init_state"])

        def frames() -> Iterator[Any]:
            yield env.render()
            for action in episode["actions"]:
                env.step(action)
                yield env.render()

        return write_video(path, frames(), fps=fps)
    frames = []
    for state in episode["env_states"]:
        env.set_state(state)
        frames.append(env.render())
    return write_video(path, frames, fps=fps)


def _state_templates(
    env_id: str, control_modes: set[str], kwargs: dict[str, Any]
) -> dict[str, Any]:
    """A state of an ms2 env of ``env_id`` per control mode (what ManiSkill2 states are mapped
    into: :func:`ms2.maniskill2_states.map_states`)."""
    templates = {}
    for mode in control_modes:
        env = _native.NativeEnv(env_id, **{**kwargs, "obs_mode": "state", "control_mode": mode})
        env.reset(seed=0)
        templates[mode] = env.get_state()
    return templates


def _map_foreign_states(traj: Any, episode: dict[str, Any], templates: dict[str, Any]) -> bool:
    """Maps ``episode``'s ``env_states`` in place from ManiSkill2 0.5.3's layout into ms2's when
    their length is not ms2's; whether it did. ``UnmappableStateError`` (a ``ValueError``) names
    the file, env and lengths of a layout neither knows."""
    from .maniskill2_states import map_states

    if "env_states" not in episode:
        return False
    template = templates[episode["control_mode"]]
    states = episode["env_states"]
    if states.shape[1] == template.size:
        return False
    source = f"{traj.path} (traj_{episode['episode_id']})"
    episode["env_states"] = map_states(states, traj.env_id, template, source=source)
    return True


def _show_episode(env_id: str, env_kwargs: dict[str, Any], episode: dict[str, Any]) -> None:
    """Shows a replayed rigid-body episode state by state in a viewer window
    (``render_mode="human"``; raises the viewer's error where there is no display)."""
    from .envs import Ms2Env

    env = Ms2Env(
        env_id,
        obs_mode="none",
        control_mode=episode["control_mode"],
        render_mode="human",
        sim_freq=float(env_kwargs.get("sim_freq", 500.0)),
        control_freq=float(env_kwargs.get("control_freq", 20.0)),
        mpm_freq=env_kwargs.get("mpm_freq"),
    )
    try:
        env.reset(seed=int(episode["episode_seed"]))
        for state in episode.get("env_states", [episode.get("env_init_state")]):
            env.set_state(state)
            env.render()
    finally:
        env.close()


def _check_soft_episodes(traj: Any, indices: list[int], use_env_states: bool, kwargs: dict) -> None:
    """Refuses, naming the file and episode, ``use_env_states`` on soft-body episodes and
    ``env_init_state`` vectors whose length is not the env's state length."""
    soft = [i for i in indices if traj.is_soft(i)]
    if not soft:
        return
    name = f"traj_{traj.episodes[soft[0]]['episode_id']}"
    if use_env_states:
        raise ValueError(
            f"{traj.path}: --use-env-states (use_env_states=True) restores per-step env_states, "
            f"but {name} is a soft-body episode that stores only env_init_state (ManiSkill2's "
            "soft-body layout); replay it without the option: the replay restores env_init_state "
            "after reset(seed) and steps the actions, deterministically"
        )
    env = _native.NativeEnv(traj.env_id, **{**kwargs, "obs_mode": "state"})
    env.reset(seed=0)
    expected = len(env.get_state())
    for i in soft:
        length = traj.h5[f"traj_{traj.episodes[i]['episode_id']}"]["env_init_state"].shape
        if length != (expected,):
            raise TrajectoryFileError(
                f"{traj.path}: traj_{traj.episodes[i]['episode_id']}: env_init_state has shape "
                f"{length} but a {traj.env_id} state in ms2 has {expected} values; ms2's state "
                "layout differs from ManiSkill2's, so ManiSkill2 soft-body trajectories open "
                "(actions, success, env_init_state) but cannot be replayed in ms2 envs"
            )


def replay(
    traj_path: str | os.PathLike[str],
    obs_mode: str | None = None,
    target_control_mode: str | None = None,
    use_env_states: bool = False,
    save_traj: bool = False,
    save_video: bool = False,
    num_workers: int = 1,
    max_retry: int = 0,
    allow_failure: bool = False,
    count: int | None = None,
    progress: bool = True,
    use_first_env_state: bool = False,
    discard_timeout: bool = False,
    vis: bool = False,
    track_hand_only: bool = False,
) -> ReplayResult:
    """Replays (and optionally converts) the episodes of ``traj_path``.

    Files ManiSkill2 0.5.3 wrote replay too: their env states (another layout) are mapped into
    ms2's (:mod:`ms2.maniskill2_states`) and, as their seeds do not give the same scenes in
    ms2, each episode starts from its first recorded state (``use_first_env_state``).

    Args:
        traj_path: the ``X.h5`` to replay (with its ``X.json``).
        obs_mode: record observations of this mode; ``None`` = the source's ``env_kwargs``
            obs mode (as ManiSkill2), none recorded when that is ``"none"`` or absent.
        target_control_mode: convert the actions closed-loop to this mode (``None``: keep).
        use_env_states: restore the recorded state after every step (no conversion; refused
            for soft-body episodes, which store only ``env_init_state``).
        use_first_env_state: restore the recorded state after reset (``env_states[0]``)
            instead of relying on the seed, then step the actions (also when converting).
        discard_timeout: count an episode that reaches the episode limit as failed, even if
            successful at its last step (ManiSkill2's ``--discard-timeout``).
        vis: show each replayed episode in a viewer window (``render_mode="human"``), state by
            state as replayed.
        save_traj: write ``X.<obs_mode>.<control_mode>.h5`` (+ ``.json``).
        save_video: write one MP4 per episode to ``X.<obs_mode>.<control_mode>.videos/``.
        num_workers: native worker threads.
        max_retry: further attempts for a conversion that fails or succeeds only past the
            env's ``max_episode_steps``: they alternate between object following and the hand
            path and tighten the trailing test; the best attempt is kept (see
            docs/trajectory_format.md, "Retry").
        track_hand_only: convert by the source's hand path alone, as ManiSkill2 does. By
            default, while both robots hold the same object, the hand is moved so that the
            converted object follows the source's object (grasps differ by a millimetre).
        allow_failure: also save episodes that do not succeed at their last step.
        count: replay only the first ``count`` episodes.
        progress: show a progress bar.
    """
    _check_int("num_workers", num_workers, 1, None)
    _check_int("max_retry", max_retry, 0, 1000)
    if count is not None:
        _check_int("count", count, 0, None)
    started, cpu_started = time.perf_counter(), time.process_time()
    with open_trajectory(traj_path) as traj:
        episodes_meta = traj.episodes[: count if count is not None else len(traj.episodes)]
        num_workers = min(num_workers, max(len(episodes_meta), 1), MAX_WORKERS)
        env_kwargs = dict(traj.env_info.get("env_kwargs") or {})
        source_modes = {ep["control_mode"] for ep in episodes_meta} or {
            env_kwargs.get("control_mode", SOURCE_CONTROL_MODE)
        }
        if target_control_mode is None and len(source_modes) > 1:
            raise ValueError(
                f"{traj_path}: episodes use several control modes {sorted(source_modes)}; pass "
                "target_control_mode"
            )
        out_mode = target_control_mode or next(iter(source_modes))
        native_kwargs = {
            key: env_kwargs[key]
            for key in (
                "reward_mode",
                "sim_freq",
                "control_freq",
                "mpm_freq",
                "exact_restore",
                "mass_matrix_substeps",
                "filtered_pair_recycling",
            )
            if key in env_kwargs
        }
        if obs_mode is None:
            obs_mode = env_kwargs.get("obs_mode")
        if obs_mode == "none":
            obs_mode = None
        native_kwargs["obs_mode"] = obs_mode or "state"
        native_kwargs["max_episode_steps"] = traj.env_info.get("max_episode_steps")
        try:
            _native.recorded_env_kwargs(traj.env_id, native_kwargs)
        except (ValueError, TypeError) as e:
            raise TrajectoryFileError(
                f"{traj_path}: its env_info (env_id {traj.env_id!r}, env_kwargs "
                f"{traj.env_info.get('env_kwargs')!r}, max_episode_steps "
                f"{traj.env_info.get('max_episode_steps')!r}) cannot make an env: {e}"
            ) from e
        _check_soft_episodes(traj, list(range(len(episodes_meta))), use_env_states, native_kwargs)
        templates = _state_templates(
            traj.env_id, {ep["control_mode"] for ep in episodes_meta}, native_kwargs
        )
        episode_limit = int(
            traj.env_info.get("max_episode_steps")
            or _native.recorded_env_kwargs(traj.env_id, native_kwargs)["max_episode_steps"]
        )
        if any(traj.is_soft(i) for i in range(len(episodes_meta))):
            # Record the resolved MPM frequency (a foreign file may lack it).
            resolved = _native.recorded_env_kwargs(traj.env_id, native_kwargs)
            env_kwargs.setdefault("mpm_freq", resolved["mpm_freq"])
        output = replay_output_path(traj_path, obs_mode, out_mode)
        if save_traj and output.resolve() == Path(traj_path).resolve():
            raise ValueError(f"{traj_path}: the replayed copy would overwrite its source")
        out_info = {
            "env_id": traj.env_id,
            "max_episode_steps": traj.env_info.get("max_episode_steps"),
            "env_kwargs": {**env_kwargs, "obs_mode": obs_mode or "none", "control_mode": out_mode},
        }
        writer = TrajectoryWriter(output, out_info) if save_traj else None
        if writer is not None:
            writer.commit()  # a valid (empty) output from the start
        result = ReplayResult(0, 0, 0.0, output if save_traj else None, 0)
        indices = list(range(len(episodes_meta)))
        try:
            with _progress(len(indices), f"replay {traj.env_id}", progress) as bar:
                for chunk in _chunks(indices, 4 * num_workers):
                    interrupts.check()
                    sources = [traj.read_episode(i) for i in chunk]
                    foreign = [_map_foreign_states(traj, ep, templates) for ep in sources]
                    try:
                        replayed = _native.replay_episodes(
                            traj.env_id,
                            sources,
                            native_kwargs,
                            target_control_mode,
                            use_env_states,
                            obs_mode is not None,
                            max_retry,
                            num_workers,
                            use_first_env_state=use_first_env_state or any(foreign),
                            track_hand_only=track_hand_only,
                        )
                    except (ValueError, TypeError) as e:
                        ids = [int(src["episode_id"]) for src in sources]
                        raise TrajectoryFileError(
                            f"{traj_path}: cannot replay episodes {ids}: {e}"
                        ) from e
                    for source, episode in zip(sources, replayed, strict=True):
                        result.num_episodes += 1
                        result.attempts += int(episode["attempts"])
                        ok = _succeeded(episode)
                        if discard_timeout and len(episode["actions"]) >= episode_limit:
                            ok = False
                        if vis:
                            _show_episode(traj.env_id, env_kwargs, episode)
                        result.num_succeeded += int(ok)
                        if not ok:
                            result.failed_episode_ids.append(int(source["episode_id"]))
                        if ok or allow_failure:
                            episode["reset_kwargs"] = source.get("reset_kwargs")
                            if writer is not None:
                                writer.append(episode, obs=episode.get("obs"))
                            if save_video:
                                video_dir = output.with_suffix(".videos")
                                path = video_dir / f"traj_{source['episode_id']}.mp4"
                                result.videos.append(
                                    _write_video(traj.env_id, env_kwargs, episode, path)
                                )
                        bar.update(1)
                    if writer is not None:
                        writer.commit()
        finally:
            if writer is not None:
                writer.close()
    result.seconds = time.perf_counter() - started
    result.cpu_seconds = time.process_time() - cpu_started
    return result


__all__ = [
    "GenerateResult",
    "ReplayResult",
    "SOFT_SOURCE_CONTROL_MODE",
    "SOURCE_CONTROL_MODE",
    "generate",
    "replay",
    "replay_output_path",
]
