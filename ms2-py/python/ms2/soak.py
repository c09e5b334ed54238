"""``ms2 bench --soak``: a long run over every task and obs mode that looks for leaks, NaN and
errors rather than speed.

Each (task, obs mode) pair gets a share of ``--steps`` env steps (default 1,000,000) in one env:
random actions, resets when an episode ends (every tenth with ``reconfigure``), and with
probability ``SET_STATE_PROBABILITY`` per step a ``set_state`` of a state recorded earlier in the
current episode (a reset may load another model, as ManiSkill2's TurnFaucet does at every reset,
and a state of one faucet is not a state of another with more handles). Shares are weighted by
cost, so the rigid-body state modes take most steps and the rendering and soft-body pairs fewer
(``WEIGHTS``); every pair runs at least ``MIN_STEPS``. Printed per pair and in total: steps,
steps/s, resident memory (RSS) at the start and end, NaN/inf observations or rewards handed out
(must be 0), and errors by type with the first messages.

``--jobs N`` runs the pairs in N worker processes (each worker soaks pair after pair, so its
memory at the end of its last pair still shows a leak across pairs); rows are printed as pairs
finish. Workers end with the soak when it is killed.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import signal
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

import numpy as np

#: Chance per step of restoring a random recorded state instead of stepping on.
SET_STATE_PROBABILITY = 0.02
#: Recorded states kept per episode (a random subset of the episode's states).
STATE_POOL = 256
#: Relative step shares: rigid-body state modes, visual modes, soft-body tasks (state), both.
WEIGHTS = {"rigid_state": 1.0, "rigid_visual": 0.05, "soft_state": 0.05, "soft_visual": 0.01}
#: Fewest steps any (task, obs mode) pair runs.
MIN_STEPS = 20
#: Small cameras for the visual modes (the soak is about robustness, not images).
SOAK_CAMERAS = {"width": 32, "height": 32}
VISUAL_MODES = ("image", "rgbd", "pointcloud", "rgbd_robot_seg", "pointcloud_robot_seg")


def rss_mb() -> float:
    """This process's current resident memory (MB), from ``/proc/self/status``."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def _non_finite(obs: Any) -> bool:
    if isinstance(obs, dict):
        return any(_non_finite(v) for v in obs.values())
    array = np.asarray(obs)
    return array.dtype.kind == "f" and not np.isfinite(array).all()


def plan(total_steps: int) -> list[tuple[str, str, int]]:
    """(env_id, obs_mode, steps) for every public task and obs mode, shares by ``WEIGHTS``."""
    import ms2

    pairs = []
    for spec in ms2.task_specs():
        for mode in spec["obs_modes"]:
            kind = ("soft" if spec["soft_bodies"] else "rigid") + (
                "_visual" if mode in VISUAL_MODES else "_state"
            )
            pairs.append((spec["env_id"], mode, WEIGHTS[kind]))
    total_weight = sum(w for *_, w in pairs)
    return [
        (env_id, mode, max(MIN_STEPS, round(total_steps * w / total_weight)))
        for env_id, mode, w in pairs
    ]


def _stop_with_parent(parent_pid: int) -> None:
    """Worker initializer: a worker ends when the soak that started it dies (killed rather than
    interrupted), instead of soaking on alone. Linux: the kernel sends it SIGTERM
    (``PR_SET_PDEATHSIG``); elsewhere the worker only checks at start."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent_pid:  # the parent died before the signal was armed
        os._exit(1)


def soak_pair(env_id: str, obs_mode: str, steps: int, seed: int) -> dict[str, Any]:
    """Runs ``steps`` env steps of one env; the pair's row (see the module docs)."""
    import ms2

    rng = np.random.default_rng(seed)
    kwargs: dict[str, Any] = {"obs_mode": obs_mode}
    if obs_mode in VISUAL_MODES:
        kwargs["camera_cfgs"] = SOAK_CAMERAS
    rss_start = rss_mb()
    errors: Counter[str] = Counter()
    messages: list[str] = []
    non_finite = set_states = resets = done_steps = 0
    pool: list[np.ndarray] = []
    started = time.perf_counter()

    def error(err: Exception) -> None:
        errors[type(err).__name__] += 1
        if len(messages) < 3:
            messages.append(f"{type(err).__name__}: {err}")

    env = ms2.Ms2Env(env_id, **kwargs)
    space = env.action_space
    obs, _ = env.reset(seed=int(rng.integers(2**32)))
    while done_steps < steps:
        try:
            if pool and rng.random() < SET_STATE_PROBABILITY:
                env.set_state(pool[int(rng.integers(len(pool)))])
                set_states += 1
            action = rng.uniform(space.low, space.high).astype(np.float32)
            obs, reward, terminated, truncated, _ = env.step(action)
            done_steps += 1
            non_finite += int(_non_finite(obs) or not math.isfinite(float(reward)))
            state = env.get_state()
            if len(pool) < STATE_POOL:
                pool.append(state)
            elif rng.random() < 0.05:
                pool[int(rng.integers(STATE_POOL))] = state
            if terminated or truncated:
                resets += 1
                env.reset(seed=int(rng.integers(2**32)), options={"reconfigure": resets % 10 == 0})
                pool.clear()  # the recorded states belong to the episode just ended
        except (ValueError, TypeError, RuntimeError) as err:
            error(err)
            done_steps += 1
            try:
                env.reset(seed=int(rng.integers(2**32)))
                pool.clear()
            except (ValueError, TypeError, RuntimeError) as err2:
                error(err2)
                break
    seconds = time.perf_counter() - started
    env.close()
    return {
        "env_id": env_id,
        "obs_mode": obs_mode,
        "steps": done_steps,
        "steps_per_s": done_steps / max(seconds, 1e-9),
        "resets": resets,
        "set_states": set_states,
        "non_finite": non_finite,
        "errors": dict(errors),
        "error_messages": messages,
        "rss_start_mb": rss_start,
        "rss_end_mb": rss_mb(),
    }


def _print_row(row: dict[str, Any]) -> None:
    print(
        f"{row['env_id']:<14} {row['obs_mode']:<21} {row['steps']:>8} steps "
        f"{row['steps_per_s']:>7.0f}/s resets {row['resets']:>5} set_state {row['set_states']:>5} "
        f"NaN {row['non_finite']} errors {row['errors'] or 0} "
        f"RSS {row['rss_start_mb']:.0f} -> {row['rss_end_mb']:.0f} MB",
        flush=True,
    )
    for msg in row["error_messages"]:
        print(f"    {msg}")


def run_soak(
    total_steps: int, seed: int = 0, env_ids: list[str] | None = None, jobs: int = 1
) -> dict[str, Any]:
    """Soaks every (task, obs mode) pair (or those of ``env_ids``), in this process or in
    ``jobs`` worker processes, printing a row per pair; returns the totals and rows."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= 64:
        raise ValueError(f"jobs must be an int in [1, 64], got {jobs!r}")
    rss_start = rss_mb()
    rows = []
    started = time.perf_counter()
    work = [
        (env_id, mode, steps, seed + i)
        for i, (env_id, mode, steps) in enumerate(plan(total_steps))
        if not env_ids or env_id in env_ids
    ]
    if jobs == 1:
        for item in work:
            rows.append(soak_pair(*item))
            _print_row(rows[-1])
    else:
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(
            max_workers=min(jobs, len(work)),
            mp_context=context,
            initializer=_stop_with_parent,
            initargs=(os.getpid(),),
        ) as ex:
            futures = [ex.submit(soak_pair, *item) for item in work]
            for future in as_completed(futures):
                rows.append(future.result())
                _print_row(rows[-1])
    total = {
        "steps": sum(r["steps"] for r in rows),
        "seconds": time.perf_counter() - started,
        "non_finite": sum(r["non_finite"] for r in rows),
        "errors": sum(sum(r["errors"].values()) for r in rows),
        "set_states": sum(r["set_states"] for r in rows),
        "resets": sum(r["resets"] for r in rows),
        "rss_start_mb": rss_start,
        "rss_end_mb": rss_mb(),
        "rows": rows,
    }
    print(
        f"soak: {total['steps']} env steps over {len(rows)} (task, obs mode) pairs in "
        f"{total['seconds']:.0f} s, {total['resets']} resets, {total['set_states']} set_state "
        f"calls; NaN/inf handed out: {total['non_finite']}; errors: {total['errors']}; "
        f"RSS {total['rss_start_mb']:.0f} MB at start, {total['rss_end_mb']:.0f} MB at end"
    )
    return total


__all__ = ["plan", "rss_mb", "run_soak", "soak_pair"]
