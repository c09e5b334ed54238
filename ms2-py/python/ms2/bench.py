"""``ms2 bench``: env steps/s and peak memory, single env and ``make_vec``.

Each configuration runs in a fresh Python process (``ms2 bench --worker ...``) so its peak
resident memory is its own. Actions are uniform random within the action space (pre-drawn, so
the timing is the env's); episodes that end are reset inside the timed loop, as a training loop
would. Observations are ``state`` by default; ``ms2 bench --visual`` measures the visual obs
modes (``rgbd`` and ``pointcloud``, ManiSkill2's two 128×128 cameras) and also prints the
triangles drawn per camera and the render adapter. Every row shows the 1-minute load average
at its start, since other processes on the machine change the figures. ``--rounds K`` runs every
state row K times, a round's rows in order so that the configurations interleave, and ends with
each row's medians: on a shared machine one run's rows can move by a few percent between rows
a few seconds apart, and the median of the per-round ratios to the single env is the steadier
figure.

``--policy scripted`` drives single envs with the task's scripted solution instead of random
actions (the soft-body tasks need it to move clay). The soft-body comparison with the paper is
``ms2 bench --visual --env-id Excavate-v0 --policy scripted --obs-modes state,rgbd`` (and the
same for ``Fill-v0``): it prints the render cost per env step, the difference between the rgbd
and state rows in wall-clock and in process CPU time (which other processes' load does not
inflate).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from typing import Any

import numpy as np

from .bench_peer import run_peer

#: ManiSkill2 0.5.3 measured on the same kind of 2-core machine, PickCube-v0, state obs,
#: 500/20 Hz: single-env steps/s per control mode (medians of 5 interleaved rounds,
#: 2026-11-29 04:21 UTC, docs/benchmarks.md; the host of that day, about twice as fast as
#: 11-25's), and its peak RSS. A stored figure: a ratio counts only against a peer run in the
#: same session.
MANISKILL2_SINGLE_STEPS_PER_S = {"pd_ee_delta_pose": 818.0, "pd_joint_delta_pos": 934.0}
#: When the figures above were measured.
MANISKILL2_SINGLE_MEASURED = "2026-11-29"
#: The task the stored figures were measured on: other tasks get no "x MS2 single" ratio.
MANISKILL2_SINGLE_ENV_ID = "PickCube-v0"
MANISKILL2_PEAK_RSS_MB = 336.0
#: ManiSkill2 0.5.3, same machine, PickCube-v0 single env in rgbd / pointcloud (lavapipe, 2
#: cameras 128×128: base_camera + hand_camera): ~18 steps/s in both.
MANISKILL2_VISUAL_STEPS_PER_S = 18.0
#: The ManiSkill2 paper (appendix, MPM parameters): "for all soft body environments with
#: rendering, a single environment runs at around 17-18 FPS" (RTX Titan GPU).
MANISKILL2_SOFT_RENDER_STEPS_PER_S = 17.5


def _cpu_seconds() -> float:
    """This process's CPU time (user + system, all threads) in seconds."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _peak_rss_mb() -> float:
    """This process's peak resident memory in MB (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _random_actions(low: np.ndarray, high: np.ndarray, count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(low, high, size=(count, *low.shape)).astype(np.float32)


def _run_single(env_id: str, control_mode: str, obs_mode: str, steps: int, policy: str) -> dict:
    import gymnasium as gym

    import ms2

    env = gym.make(env_id, obs_mode=obs_mode, control_mode=control_mode)
    space = env.action_space
    actions = _random_actions(space.low, space.high, 1024, seed=1)
    scripted = ms2.ScriptedPolicy(env) if policy == "scripted" else None

    def reset(seed: int | None = None) -> None:
        env.reset(seed=seed)
        if scripted is not None:
            scripted.reset()

    def action(i: int) -> np.ndarray:
        return scripted.act() if scripted is not None else actions[i % len(actions)]

    reset(seed=0)
    for i in range(10):  # warm-up
        env.step(action(i))
    reset(seed=1)
    cpu_started = _cpu_seconds()
    started = time.perf_counter()
    for i in range(steps):
        _obs, _reward, terminated, truncated, _info = env.step(action(i))
        if terminated or truncated:
            reset()
    elapsed = time.perf_counter() - started
    cpu = _cpu_seconds() - cpu_started
    return {
        "steps_per_s": steps / elapsed,
        "seconds": elapsed,
        "cpu_ms_per_step": 1e3 * cpu / steps,
        "env_steps": steps,
        "triangles_per_camera": env.unwrapped._native.triangles_per_camera(),
    }


def _run_vec(env_id: str, control_mode: str, obs_mode: str, num_envs: int, steps: int) -> dict:
    import ms2

    envs = ms2.make_vec(env_id, num_envs=num_envs, obs_mode=obs_mode, control_mode=control_mode)
    space = envs.single_action_space
    actions = _random_actions(space.low, space.high, 256 * num_envs, seed=1)
    actions = actions.reshape(256, num_envs, *space.shape)
    envs.reset(seed=0)
    for i in range(5):  # warm-up
        envs.step(actions[i])
    batches = max(1, steps // num_envs)
    cpu_started = _cpu_seconds()
    started = time.perf_counter()
    for i in range(batches):
        envs.step(actions[i % len(actions)])
    elapsed = time.perf_counter() - started
    cpu = _cpu_seconds() - cpu_started
    return {
        "steps_per_s": batches * num_envs / elapsed,
        "seconds": elapsed,
        "cpu_ms_per_step": 1e3 * cpu / (batches * num_envs),
        "env_steps": batches * num_envs,
        "triangles_per_camera": envs._native.triangles_per_camera(),
    }


def _worker(args: argparse.Namespace) -> int:
    spec = json.loads(args.worker)
    obs_mode = spec.get("obs_mode", "state")
    if spec["kind"] == "single":
        policy = spec.get("policy", "random")
        result = _run_single(spec["env_id"], spec["control_mode"], obs_mode, spec["steps"], policy)
    else:
        result = _run_vec(
            spec["env_id"], spec["control_mode"], obs_mode, spec["num_envs"], spec["steps"]
        )
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


def _load() -> float:
    """The 1-minute load average."""
    return os.getloadavg()[0]


def _configs(num_envs_list: list[int]) -> list[tuple[str, int]]:
    return [("single", 1)] + [("vec", n) for n in num_envs_list]


def _run_rows(
    env_id: str,
    steps: int,
    groups: list[dict],
    num_envs_list: list[int],
    format_row: Any,
    peer_python: str | None = None,
) -> list[dict]:
    """Runs, for each group (``control_mode`` and ``obs_mode``), a single env and ``make_vec``
    with each of ``num_envs_list`` envs, each in a fresh process; prints a row per run as
    ``format_row(spec, result, single_env_steps_per_s)`` followed by the load average, and
    returns the rows (spec, result and load). With ``peer_python``, ManiSkill2 0.5.3's single
    env runs right after ms2's (kind ``peer``), and later rows compare with it."""
    rows = []
    for group in groups:
        single = None
        single_rss = None
        peer = None
        for kind, n in _configs(num_envs_list):
            spec = {"kind": kind, "env_id": env_id, **group, "num_envs": n, "steps": steps}
            load = _load()
            result = _spawn(spec)
            if kind == "single":
                single = result["steps_per_s"]
                single_rss = result["peak_rss_mb"]
                if peer_python:
                    peer_load = _load()
                    peer = run_peer(peer_python, spec)
                    peer["load_1min"] = peer_load
            elif n > 1 and single_rss is not None:
                # Peak memory each env beyond the first adds (the single env holds one).
                result["mb_per_extra_env"] = (result["peak_rss_mb"] - single_rss) / (n - 1)
            if peer is not None:
                result["peer_steps_per_s"] = peer["steps_per_s"]
            print(f"{format_row(spec, result, single)} {load:>5.1f}", flush=True)
            rows.append({**spec, **result, "load_1min": load})
            if kind == "single" and peer is not None:
                peer_spec = {**spec, "kind": "peer"}
                peer["peer_steps_per_s"] = peer["steps_per_s"]
                peer_row = format_row(peer_spec, peer, single)
                print(f"{peer_row} {peer['load_1min']:>5.1f}", flush=True)
                rows.append({**peer_spec, **peer})
    return rows


def _runner_name(kind: str, n: int) -> str:
    if kind == "peer":
        return "ManiSkill2 0.5.3"
    return "gym.make (1 env)" if kind == "single" else f"make_vec({n})"


def _soak(args: argparse.Namespace) -> int:
    """``ms2 bench --soak``: see :mod:`ms2.soak`."""
    from .soak import run_soak

    steps = 1_000_000 if args.steps is None else args.steps
    if steps < 1:
        raise ValueError(f"--steps must be at least 1, got {steps}")
    print(
        f"ms2 bench --soak: {steps} env steps over every task and obs mode, load average "
        f"{os.getloadavg()[0]:.1f}",
        flush=True,
    )
    total = run_soak(steps, jobs=args.jobs)
    _write_json(args.json, total)
    return 0 if total["non_finite"] == 0 and total["errors"] == 0 else 1


def _task_spec(env_id: str) -> dict:
    """The registered spec of ``env_id`` (a ``ValueError`` naming the valid ids otherwise)."""
    from . import _native

    specs = {s["env_id"]: s for s in _native.task_specs()}
    if env_id not in specs:
        raise ValueError(f"unknown env id {env_id!r}; valid: {sorted(specs)}")
    return specs[env_id]


def _default_control_modes(env_id: str) -> str:
    """The control modes benchmarked when none are given: ``pd_ee_delta_pose`` and
    ``pd_joint_delta_pos`` (the visual rows take ``pd_joint_delta_pos``), or the task's default
    mode for the mobile robots, which have neither (``base_pd_joint_vel_arm_pd_joint_vel``)."""
    default = _task_spec(env_id)["default_control_mode"]
    return default if default.startswith("base_") else "pd_ee_delta_pose,pd_joint_delta_pos"


def _cmd_bench(args: argparse.Namespace) -> int:
    if args.worker:
        return _worker(args)
    if args.soak:
        return _soak(args)
    num_envs_list = [int(n) for n in args.num_envs.split(",") if n]
    if args.rounds < 1:
        raise ValueError(f"--rounds must be at least 1, got {args.rounds}")
    if args.visual and args.rounds != 1:
        raise ValueError(f"--rounds is for the state rows (--visual runs once), got {args.rounds}")
    if args.visual:
        return _bench_visual(args, num_envs_list)
    steps = args.steps or 4000
    given = args.control_modes or _default_control_modes(args.env_id)
    control_modes = [m for m in given.split(",") if m]
    from . import _native

    print(
        f"ms2 bench: {args.env_id}, obs_mode=state, {args.policy} actions, 500 Hz physics / 20 Hz "
        f"control, {os.cpu_count()} cores, vector pool {_native.num_threads()} threads, "
        f"{steps} env steps per row"
    )
    mode_width = max([20, *(len(m) for m in control_modes)])
    header = (
        f"{'control_mode':<{mode_width}} {'runner':<18} {'steps/s':>9} {'x our single':>12} "
        f"{'x MS2 single':>12} {'peak RSS MB':>11} {'load':>5}"
    )
    print(header)
    print("-" * len(header))

    stored = MANISKILL2_SINGLE_STEPS_PER_S if args.env_id == MANISKILL2_SINGLE_ENV_ID else {}

    def state_row(spec: dict, result: dict, single: float) -> str:
        peer = stored.get(spec["control_mode"])
        vs_peer = f"{result['steps_per_s'] / peer:.2f}" if peer else "-"
        return (
            f"{spec['control_mode']:<{mode_width}} "
            f"{_runner_name(spec['kind'], spec['num_envs']):<18} "
            f"{result['steps_per_s']:>9.0f} {result['steps_per_s'] / single:>12.2f} "
            f"{vs_peer:>12} {result['peak_rss_mb']:>11.0f}"
        )

    if args.policy == "scripted" and num_envs_list:
        print("(--policy scripted drives single envs only: make_vec rows skipped)")
        num_envs_list = []
    specs = [
        {"control_mode": control_mode, "obs_mode": "state", "policy": args.policy}
        for control_mode in control_modes
    ]
    rows = []
    for round_index in range(1, args.rounds + 1):
        if args.rounds > 1:
            print(f"round {round_index} of {args.rounds}", flush=True)
        round_rows = _run_rows(args.env_id, steps, specs, num_envs_list, state_row)
        rows.extend({**row, "round": round_index} for row in round_rows)
    if args.rounds > 1:
        _print_round_medians(_round_medians(rows), args.rounds, mode_width)
    if stored:
        print(
            "x MS2 single: against ManiSkill2 0.5.3's stored figures "
            f"({MANISKILL2_SINGLE_ENV_ID}, {MANISKILL2_SINGLE_MEASURED}, single env, not measured "
            "in this run): "
            + ", ".join(f"{m} {v:.0f} steps/s" for m, v in stored.items())
            + f", peak RSS {MANISKILL2_PEAK_RSS_MB:.0f} MB"
        )
    else:
        print(
            f"x MS2 single: no stored ManiSkill2 figure for {args.env_id} (only for "
            f"{MANISKILL2_SINGLE_ENV_ID}); scripts/bench_state_side_by_side.py runs both"
        )
    _write_json(args.json, rows)
    return 0


def _round_medians(rows: list[dict]) -> list[dict]:
    """Per row (control mode and runner) over the rounds of ``rows`` (each with its ``round``):
    the median steps/s, and the median, lowest and highest ratio to the single env of the same
    round and control mode. In the order the rows first appear."""
    singles = {
        (row["round"], row["control_mode"]): row["steps_per_s"]
        for row in rows
        if row["kind"] == "single"
    }
    grouped: dict[tuple[str, str, int], list[tuple[float, float]]] = {}
    for row in rows:
        key = (row["control_mode"], row["kind"], row["num_envs"])
        single = singles[(row["round"], row["control_mode"])]
        grouped.setdefault(key, []).append((row["steps_per_s"], row["steps_per_s"] / single))
    medians = []
    for (control_mode, kind, num_envs), values in grouped.items():
        ratios = [ratio for _, ratio in values]
        medians.append(
            {
                "control_mode": control_mode,
                "kind": kind,
                "num_envs": num_envs,
                "rounds": len(values),
                "median_steps_per_s": statistics.median(v for v, _ in values),
                "median_ratio": statistics.median(ratios),
                "min_ratio": min(ratios),
                "max_ratio": max(ratios),
            }
        )
    return medians


def _print_round_medians(medians: list[dict], rounds: int, mode_width: int) -> None:
    """Prints :func:`_round_medians`' table."""
    print(
        f"medians over {rounds} rounds ('x our single': against the same round's single env; "
        "lowest-highest)"
    )
    for m in medians:
        runner = _runner_name(m["kind"], m["num_envs"])
        print(
            f"{m['control_mode']:<{mode_width}} {runner:<18} {m['median_steps_per_s']:>9.0f} "
            f"{m['median_ratio']:>12.2f}   {m['min_ratio']:.2f}-{m['max_ratio']:.2f}"
        )


def _bench_visual(args: argparse.Namespace, num_envs_list: list[int]) -> int:
    """``ms2 bench --visual``: rgbd / pointcloud steps/s, memory and triangles per camera; with
    a ``state`` obs mode among them, the render cost per env step."""
    from . import _native

    # Envs with soft bodies (their spec says so) are compared with the paper's soft-body figure.
    soft = any(s["env_id"] == args.env_id and s["soft_bodies"] for s in _native.task_specs())
    steps = args.steps or (200 if soft else 1000)
    obs_modes = [m for m in args.obs_modes.split(",") if m]
    mobile = _task_spec(args.env_id)["default_control_mode"].startswith("base_")
    # The first mode given, else the last default (pd_joint_delta_pos, or the mobile default).
    given = args.control_modes or _default_control_modes(args.env_id).split(",")[-1]
    control_mode = given.split(",")[0]
    if args.policy == "scripted" and num_envs_list:
        print("(--policy scripted drives single envs only: make_vec rows skipped)")
        num_envs_list = []
    cameras = (
        "overhead_camera_0-2 400x160 (fused in the base frame)"
        if mobile
        else "base_camera + hand_camera 128x128"
    )
    # ManiSkill2's visual figure is PickCube's (two cameras); the mobile tasks have three
    # cameras and no recorded ManiSkill2 figure.
    peer = MANISKILL2_SOFT_RENDER_STEPS_PER_S if soft else MANISKILL2_VISUAL_STEPS_PER_S
    if mobile and not soft:
        peer = None
    print(
        f"ms2 bench --visual: {args.env_id}, {control_mode}, {args.policy} actions, 500 Hz "
        f"physics / 20 Hz control, cameras {cameras}, "
        f"{os.cpu_count()} cores, renderer {_native.render_adapter()}, {steps} env steps per row"
    )
    header = (
        f"{'obs_mode':<11} {'runner':<18} {'steps/s':>9} {'cpu ms/step':>11} "
        f"{'x our single':>12} {'x MS2 single':>12} {'peak RSS MB':>11} {'MB/extra env':>12} "
        f"{'triangles/cam':>13} {'load':>5}"
    )
    print(header)
    print("-" * len(header))

    def visual_row(spec: dict, result: dict, single: float) -> str:
        # Measured in this run when --peer-python is given, else the recorded figure.
        reference = result.get("peer_steps_per_s", peer)
        vs_peer = "-" if reference is None else f"{result['steps_per_s'] / reference:.2f}"
        extra = result.get("mb_per_extra_env")
        triangles = result["triangles_per_camera"]
        return (
            f"{spec['obs_mode']:<11} {_runner_name(spec['kind'], spec['num_envs']):<18} "
            f"{result['steps_per_s']:>9.1f} {result['cpu_ms_per_step']:>11.1f} "
            f"{result['steps_per_s'] / single:>12.2f} "
            f"{vs_peer:>12} "
            f"{result['peak_rss_mb']:>11.0f} {'-' if extra is None else f'{extra:.0f}':>12} "
            f"{'-' if triangles is None else triangles:>13}"
        )

    specs = [
        {"control_mode": control_mode, "obs_mode": obs_mode, "policy": args.policy}
        for obs_mode in obs_modes
    ]
    peer_python = args.peer_python or os.environ.get("MS2_PEER_PYTHON")
    rows = _run_rows(args.env_id, steps, specs, num_envs_list, visual_row, peer_python)
    _print_render_cost(rows)
    if soft:
        print(
            f"ManiSkill2 paper: soft-body envs with rendering ~{peer:.1f} steps/s single env on "
            f"an RTX Titan GPU (MPM on the GPU); ms2 runs MPM and rendering on the CPU cores above"
        )
    elif mobile and not peer_python:
        print("ManiSkill2 0.5.3: no figure recorded for the mobile tasks (three cameras)")
    elif not peer_python:
        print(
            f"ManiSkill2 0.5.3 on this machine (single env, lavapipe, same cameras), recorded "
            f"earlier: rgbd and pointcloud ~{peer:.0f} steps/s, peak RSS 336-480 MB; measure it "
            f"in the same run with --peer-python (a Python with mani-skill2==0.5.3)"
        )
    _write_json(args.json, rows)
    return 0


def _print_render_cost(rows: list[dict]) -> None:
    """Prints, for each visual single-env row measured alongside a ``state`` one, the render
    cost per env step: wall-clock and CPU ms/step of the visual row minus the state row's."""
    singles = {r["obs_mode"]: r for r in rows if r["kind"] == "single"}
    state = singles.get("state")
    if state is None:
        return
    for obs_mode, row in singles.items():
        if obs_mode == "state":
            continue
        wall = 1e3 / row["steps_per_s"] - 1e3 / state["steps_per_s"]
        cpu = row["cpu_ms_per_step"] - state["cpu_ms_per_step"]
        print(
            f"render cost per env step ({obs_mode} minus state, single env): wall {wall:.1f} ms, "
            f"CPU {cpu:.1f} ms"
        )


def _write_json(path: str | None, rows: list[dict] | dict) -> None:
    if path:
        tmp = f"{path}.tmp"
        with open(tmp, "w") as f:
            json.dump(rows, f, indent=2)
        os.replace(tmp, path)


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Adds the ``bench`` subcommand to the ``ms2`` command line."""
    p = sub.add_parser(
        "bench",
        help="benchmark env steps/s (single env and make_vec) and memory",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--env-id", default="PickCube-v0", help="task id")
    p.add_argument(
        "--steps",
        type=int,
        default=None,
        help="env steps per configuration (None: 4000; --visual: 1000, soft-body envs 200)",
    )
    p.add_argument(
        "--visual",
        action="store_true",
        help="benchmark the visual obs modes (rgbd, pointcloud) instead of state",
    )
    p.add_argument("--obs-modes", default="rgbd,pointcloud", help="visual obs modes (--visual)")
    p.add_argument("--num-envs", default="1,2,4,8,16", help="comma-separated make_vec sizes")
    p.add_argument(
        "--control-modes",
        default=None,
        help="comma-separated (None: pd_ee_delta_pose,pd_joint_delta_pos, or the task's default "
        "mode on the mobile robots; --visual: the first one given, else pd_joint_delta_pos or the "
        "mobile default)",
    )
    p.add_argument(
        "--policy",
        choices=["random", "scripted"],
        default="random",
        help="actions: uniform random or the task's scripted solution (single envs)",
    )
    p.add_argument(
        "--peer-python",
        default=None,
        help="--visual: a Python with mani-skill2==0.5.3 installed; its single env is measured "
        "after each of ms2's, interleaved (also MS2_PEER_PYTHON)",
    )
    p.add_argument(
        "--soak",
        action="store_true",
        help="robustness soak instead: --steps (default 1,000,000) env steps over every task and "
        "obs mode with resets and set_state of recorded states; reports RSS, NaN and errors",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="--soak: worker processes soaking (task, obs mode) pairs in parallel",
    )
    p.add_argument(
        "--rounds",
        type=int,
        default=1,
        help="state rows: run every row this many times, the rows of a round in order (so the "
        "configurations interleave), and end with each row's medians over the rounds: steps/s "
        "and 'x our single' against the same round's single env, with its range",
    )
    p.add_argument("--json", default=None, help="also write the rows to this JSON file")
    p.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    p.set_defaults(func=_cmd_bench)
