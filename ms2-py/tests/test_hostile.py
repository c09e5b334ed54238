"""Hostile and careless input (issue #15), property-based with hypothesis.

Every property asserts the same contract: a rejection is a ``ValueError`` or ``TypeError`` whose
message names the bad value; an accepted input never yields a NaN / infinite observation or
reward; no call takes longer than ``CALL_DEADLINE_S`` (a generous bound against hangs, not a
speed test); and the process never aborts (an abort would kill the test run itself; the
previously aborting inputs also run in a child process, whose exit status is checked).

Example counts are small for CI (profile ``ci``, the default); ``pytest --hypothesis-profile
heavy ms2-py/tests/test_hostile.py`` runs ~20x more for a local soak.
"""

from __future__ import annotations

import math
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import ms2
import numpy as np
import pytest
from conftest import leaves
from hypothesis import given
from hypothesis import strategies as st
from ms2 import cli

#: No single call may take longer than this (s): a bound against hangs, generous on purpose.
CALL_DEADLINE_S = 30.0


_pool = ThreadPoolExecutor(max_workers=1)


def bounded(fn, *args, **kwargs):
    """Runs ``fn`` and returns its result, failing if it takes longer than CALL_DEADLINE_S."""
    future = _pool.submit(fn, *args, **kwargs)
    return future.result(timeout=CALL_DEADLINE_S)


def assert_finite(obs, reward=0.0):
    for path, array in leaves(obs):
        if array.dtype.kind == "f":
            assert np.isfinite(array).all(), f"non-finite observation at {path}"
    assert math.isfinite(float(reward)), f"non-finite reward {reward}"


def assert_names_value(err: Exception, *candidates) -> None:
    """The message of a rejection names (one of) the offending values or keys."""
    msg = str(err)
    texts = set()
    for c in candidates:
        texts.add(str(c))
        texts.add(repr(c))
        if isinstance(c, float) and c.is_integer() and abs(c) < 1e16:
            texts.add(str(int(c)))
    assert any(t in msg for t in texts), f"{type(err).__name__}: {msg!r} names none of {texts}"


# ---- env configs ----

_numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, 1, 10, 20, 100, 500, 1000, 2000, 1e-3, 1e9, True, "500", None]),
)
_configs = st.fixed_dictionaries(
    {},
    optional={
        "obs_mode": st.sampled_from(["state", "state_dict", "rgbd", "bogus", 3, None]),
        "control_mode": st.sampled_from(
            ["pd_joint_delta_pos", "pd_ee_delta_pose", "pd_joint_pos", "nope", 1.5, None]
        ),
        "reward_mode": st.sampled_from(["sparse", "dense", "normalized_dense", "x", None]),
        "sim_freq": _numbers,
        "control_freq": _numbers,
        "max_episode_steps": st.one_of(
            st.integers(min_value=-(2**40), max_value=2**40), st.floats(), st.none()
        ),
        "mpm_freq": st.sampled_from([None, 1000.0, 1e9, -1.0]),
        "camera_cfgs": st.sampled_from(
            [None, {"width": 16}, {"base_camera": 5}, {"width": -1}, {"nonsense": 1}, []]
        ),
    },
)


def _is_heavy(cfg: dict) -> bool:
    """A config whose accepted env would render (slow to make on the CPU rasteriser)."""
    return cfg.get("obs_mode") == "rgbd" or cfg.get("camera_cfgs") is not None


@given(env_id=st.sampled_from(["PickCube-v0", "Dummy-v0", "NoSuch-v0"]), cfg=_configs)
def test_env_configs_are_accepted_cleanly_or_refused_by_name(env_id, cfg):
    if _is_heavy(cfg):
        cfg = {**cfg, "obs_mode": "state", "camera_cfgs": None}
    try:
        env = bounded(ms2.Ms2Env, env_id, **cfg)
    except (ValueError, TypeError) as err:
        assert_names_value(err, env_id, *cfg.keys(), *cfg.values())
        return
    obs, _ = bounded(env.reset, seed=0)
    assert_finite(obs)
    for _ in range(2):
        obs, reward, *_ = bounded(env.step, env.action_space.sample())
        assert_finite(obs, reward)


# ---- actions ----

_elements = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, 1.0, -1.0, 1e30, -1e30, 1e-45]),
)


@st.composite
def _actions(draw):
    kind = draw(st.sampled_from(["right", "right", "wrong_len", "2d", "complex", "str", "int"]))
    if kind == "right":
        return np.array(draw(st.lists(_elements, min_size=8, max_size=8)))
    if kind == "wrong_len":
        return np.zeros(draw(st.integers(0, 20).filter(lambda n: n != 8)))
    if kind == "2d":
        return np.zeros((2, 8))
    if kind == "complex":
        return np.zeros(8) + 1j
    if kind == "str":
        return np.array(["a"] * 8)
    return np.array(draw(st.lists(st.integers(-(2**31), 2**31), min_size=8, max_size=8)))


@pytest.fixture(scope="module")
def pick_env():
    env = ms2.Ms2Env("PickCube-v0", obs_mode="state")
    env.reset(seed=0)
    return env


@given(action=_actions())
def test_actions_step_finitely_or_are_refused_by_name(pick_env, action):
    try:
        obs, reward, terminated, truncated, info = bounded(pick_env.step, action)
    except (ValueError, TypeError) as err:
        assert "action" in str(err), str(err)
        return
    assert_finite(obs, reward)


# ---- states ----


@pytest.fixture(scope="module")
def recorded_states():
    """States of a real PickCube episode (scripted policy, 40 steps)."""
    env = ms2.Ms2Env("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
    env.reset(seed=3)
    policy = ms2.ScriptedPolicy(env)
    policy.reset()
    states = [env.get_state()]
    for _ in range(40):
        env.step(policy.act())
        states.append(env.get_state())
    return env, np.stack(states)


@given(
    data=st.data(),
    values=st.lists(
        st.one_of(
            st.floats(allow_nan=False, allow_infinity=False, width=32),
            st.floats(min_value=-5, max_value=5, width=32),
        ),
        min_size=1,
        max_size=4,
    ),
)
def test_set_state_refuses_impossible_states_and_never_yields_nan(recorded_states, data, values):
    env, states = recorded_states
    state = states[data.draw(st.integers(0, len(states) - 1))].copy()
    indices = [data.draw(st.integers(0, state.size - 1)) for _ in values]
    state[indices] = np.array(values, dtype=np.float32)
    try:
        bounded(env.set_state, state)
    except ValueError as err:
        assert "state[" in str(err), str(err)
        assert any(f"state[{i}]" in str(err) for i in indices) or "quaternion" in str(err)
    else:
        for _ in range(3):
            try:
                obs, reward, *_ = bounded(env.step, np.zeros(7, np.float32))
            except RuntimeError as err:  # refused, never handed out
                assert "non-finite" in str(err)
                break
            assert_finite(obs, reward)
    obs, _ = bounded(env.reset, seed=1)  # a plain reset always restores a good episode
    assert_finite(obs)


def test_states_of_real_episodes_are_accepted(recorded_states):
    env, states = recorded_states
    for state in states:
        env.set_state(state)
        np.testing.assert_array_equal(env.get_state(), state)


# ---- seeds and reset options ----

_seeds = st.one_of(
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True),
    st.booleans(),
    st.sampled_from([None, "1", [1], 2**64 - 1, 2**64]),
)


@given(seed=_seeds, options=st.sampled_from([None, {}, {"reconfigure": False}, [1], {"x": 1}]))
def test_reset_seeds_and_options(pick_env, seed, options):
    try:
        obs, _ = bounded(pick_env.reset, seed=seed, options=options)
    except (ValueError, TypeError) as err:
        assert_names_value(err, seed, options, "options")
        return
    assert_finite(obs)


@given(seed=st.one_of(_seeds, st.lists(_seeds, min_size=1, max_size=3)))
def test_vector_reset_seeds(seed):
    envs = _vec()
    try:
        obs, _ = bounded(envs.reset, seed=seed)
    except (ValueError, TypeError) as err:
        items = seed if isinstance(seed, list) else [seed]
        assert_names_value(err, seed, *items, "seed")
        return
    assert_finite(obs)


_VEC = []


def _vec():
    if not _VEC:
        _VEC.append(ms2.make_vec("Dummy-v0", num_envs=2, obs_mode="state"))
    return _VEC[0]


@given(
    num_envs=st.one_of(
        st.integers(-(2**64), 2**64).filter(lambda n: not 5 <= n <= 4096),  # no slow big makes
        st.floats(),
        st.booleans(),
    )
)
def test_num_envs(num_envs):
    if isinstance(num_envs, int) and not isinstance(num_envs, bool) and 1 <= num_envs <= 4:
        envs = bounded(ms2.make_vec, "Dummy-v0", num_envs=num_envs)
        assert envs.num_envs == num_envs
        return
    with pytest.raises((ValueError, TypeError)) as info:
        bounded(ms2.make_vec, "Dummy-v0", num_envs=num_envs)
    assert_names_value(info.value, num_envs)


def test_closed_env_says_so():
    env = ms2.Ms2Env("Dummy-v0")
    env.close()
    for call in (lambda: env.step(np.zeros(2)), lambda: env.reset(seed=0), env.get_state):
        with pytest.raises(ValueError, match="closed"):
            call()


# ---- CLI ----


@given(
    count=st.integers(-(2**65), 2**65),
    workers=st.integers(-5, 10**6),
)
def test_replay_cli_arguments(tmp_path_factory, capsys, count, workers):
    traj = _trajectory(tmp_path_factory)
    argv = ["replay", "--traj-path", str(traj), "-q", "--count", str(count)]
    argv += ["--num-workers", str(workers)]
    code = bounded(cli.main, argv)
    err = capsys.readouterr().err
    if count < 0 or workers < 1:
        assert code == 2 and ("count" in err or "num_workers" in err), err
    else:
        assert code == 0, err


_TRAJ = []


def _trajectory(factory) -> Path:
    """A two-episode scripted Dummy-v0 trajectory file."""
    if not _TRAJ:
        from ms2 import demos

        path = factory.mktemp("traj") / "dummy.h5"
        demos.generate(
            "Dummy-v0",
            2,
            path,
            policy="scripted",
            progress=False,
            control_mode="pd_joint_delta_pos",
        )
        _TRAJ.append(path)
    return _TRAJ[0]


@given(
    n=st.integers(-3, 3),
    seed=st.sampled_from([0, -1, 2**64 - 1, 2**64 - 3, 2**70]),
    workers=st.sampled_from([1, 0, 100000]),
    output=st.sampled_from(["ok", "dir", "under_file", "proc"]),
)
def test_demos_generate_cli_arguments(tmp_path, capsys, n, seed, workers, output):
    (tmp_path / "a_dir.h5").mkdir(exist_ok=True)
    (tmp_path / "file.json").write_text("{}")
    out = {
        "ok": tmp_path / "out" / "d.h5",
        "dir": tmp_path / "a_dir.h5",
        "under_file": tmp_path / "file.json" / "sub" / "d.h5",
        "proc": Path("/proc/ms2_denied/d.h5"),
    }[output]
    argv = ["demos", "generate", "Dummy-v0", "--policy", "scripted", "-c", "pd_joint_delta_pos"]
    argv += [
        "-n",
        str(n),
        "--seed",
        str(seed),
        "--workers",
        str(workers),
        "--output",
        str(out),
        "-q",
    ]
    code = bounded(cli.main, argv)
    err = capsys.readouterr().err
    bad = n < 1 or seed < 0 or seed + 4 * n + 20 - 1 > 2**64 - 1 or workers < 1 or output != "ok"
    if bad:
        assert code == 2, err
        assert "Traceback" not in err
    else:
        assert code == 0, err
        assert out.exists()


# ---- the process never aborts ----

_ABORTERS = r"""
import ms2, numpy as np
for make in (
    lambda: ms2.make_vec("PickCube-v0", num_envs=2**40),
    lambda: ms2.Ms2Env("PickCube-v0", sim_freq=1e9),
    lambda: ms2.Ms2Env("PickCube-v0", sim_freq=1e8, control_freq=1),
):
    try:
        make()
        raise SystemExit("accepted")
    except ValueError as err:
        print("refused:", err)
env = ms2.Ms2Env("PickCube-v0", obs_mode="state")
env.reset(seed=0)
s = env.get_state()
s[20] = 10.0
try:
    env.set_state(s)
    raise SystemExit("accepted")
except ValueError as err:
    print("refused:", err)
o, r, *_ = env.step(np.zeros(8, np.float32))
assert np.isfinite(o).all() and np.isfinite(r)
print("ok")
"""


def test_inputs_that_used_to_abort_or_hang_are_refused_in_a_child_process():
    proc = subprocess.run(
        [sys.executable, "-c", _ABORTERS],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "num_envs must be in 1..=4096, got 1099511627776" in out
    assert "sim_freq must be in [10, 10000] Hz, got 1000000000" in out
    assert "state[20] = 10 (qpos of panda_joint1)" in out
    assert out.strip().endswith("ok")


# ---- restoring states ----


def test_recorded_fixture_states_are_accepted():
    """Every state recorded by real episodes (the prev_main fixtures) passes the bounds."""
    from ms2.trajectory import open_trajectory

    fixtures = Path(__file__).parent / "fixtures" / "prev_main"
    for h5 in sorted(fixtures.glob("*Cube-v0.h5")):
        with open_trajectory(h5) as traj:
            env = ms2.Ms2Env(traj.env_id, obs_mode="state")
            env.reset(seed=0)
            for i in range(len(traj)):
                for state in traj.read_episode(i)["env_states"]:
                    env.set_state(state)


def _scripted_run(env_id: str, mode: str, exact: bool, steps: int = 50):
    """A scripted episode from seed 5: its actions and the state before each step and after."""
    env = ms2.Ms2Env(env_id, obs_mode="state", control_mode=mode, exact_restore=exact)
    env.reset(seed=5)
    policy = ms2.ScriptedPolicy(env)
    policy.reset()
    actions, states = [], [env.get_state()]
    for _ in range(steps):
        actions.append(policy.act())
        env.step(actions[-1])
        states.append(env.get_state())
    return actions, states


def _continue_in_fresh_env(env_id, mode, exact, state, actions):
    """Restores ``state`` into a new env (reset with another seed first) and steps ``actions``."""
    fresh = ms2.Ms2Env(env_id, obs_mode="state", control_mode=mode, exact_restore=exact)
    fresh.reset(seed=7)
    fresh.set_state(state)
    run = []
    for a in actions:
        fresh.step(a)
        run.append(fresh.get_state())
    return np.stack(run)


@pytest.mark.parametrize(
    "env_id,mode", [("StackCube-v0", "pd_ee_delta_pose"), ("PickCube-v0", "pd_joint_delta_pos")]
)
def test_exact_restore_continues_bit_for_bit_in_a_fresh_env(env_id, mode):
    """Issue #15 item 7: with ``exact_restore=True`` a state restored mid-episode into another
    env (in contact: the cube is grasped, or pushed) continues exactly as the original run."""
    actions, states = _scripted_run(env_id, mode, exact=True)
    for start in (0, 10, 30):
        run = _continue_in_fresh_env(env_id, mode, True, states[start], actions[start : start + 20])
        np.testing.assert_array_equal(run, np.stack(states[start + 1 : start + 21]))


def test_default_restore_is_exact_from_an_episode_start_and_in_the_same_env():
    """Without ``exact_restore``: an episode replayed from its first state in a fresh env, and a
    state restored mid-episode into the env that recorded it, both reproduce the run exactly;
    only a mid-episode restore into a *fresh* env drifts (documented in
    docs/trajectory_format.md, measured here so the docs' figure stays honest)."""
    env_id, mode = "StackCube-v0", "pd_ee_delta_pose"
    actions, states = _scripted_run(env_id, mode, exact=False)
    run = _continue_in_fresh_env(env_id, mode, False, states[0], actions[:30])
    np.testing.assert_array_equal(run, np.stack(states[1:31]))
    # The same env: rewind to step 10 and step again.
    env = ms2.Ms2Env(env_id, obs_mode="state", control_mode=mode)
    env.reset(seed=5)
    for a in actions[:10]:
        env.step(a)
    assert np.array_equal(env.get_state(), states[10])
    saved = env.get_state()
    for a in actions[10:20]:
        env.step(a)
    env.set_state(saved)
    again = []
    for a in actions[10:20]:
        env.step(a)
        again.append(env.get_state())
    np.testing.assert_array_equal(np.stack(again), np.stack(states[11:21]))
    drift = _continue_in_fresh_env(env_id, mode, False, states[10], actions[10:30])
    worst = float(np.abs(drift - np.stack(states[11:31])).max())
    assert worst > 0.0, "a fresh env reproduced the run without exact_restore: update the docs"


def test_exact_restore_is_recorded_only_when_on_and_must_be_a_bool():
    from ms2 import _native

    on = _native.recorded_env_kwargs("PickCube-v0", {"obs_mode": "state", "exact_restore": True})
    assert on["exact_restore"] is True
    off = _native.recorded_env_kwargs("PickCube-v0", {"obs_mode": "state"})
    assert "exact_restore" not in off  # ManiSkill2 has no such keyword
    with pytest.raises(TypeError, match="exact_restore must be a bool, got 1"):
        ms2.Ms2Env("PickCube-v0", exact_restore=1)


def test_mass_matrix_substeps_is_checked_recorded_when_not_default_and_changes_the_run():
    """Issue #21: ``mass_matrix_substeps`` (ms2's own keyword) must be an int in [1, 1000];
    the default agrees with the native one; a trajectory records it only when it is not the
    default; 1 (rebuild every substep) gives another run than the default, each repeatable."""
    from ms2 import _native
    from ms2.envs import DEFAULT_MASS_MATRIX_SUBSTEPS

    env = ms2.Ms2Env("PickCube-v0", obs_mode="state")
    assert env.mass_matrix_substeps == DEFAULT_MASS_MATRIX_SUBSTEPS
    assert ms2.Ms2Env("Fill-v0", obs_mode="state").mass_matrix_substeps == 1  # soft: exact
    assert env._native.config()["mass_matrix_substeps"] == DEFAULT_MASS_MATRIX_SUBSTEPS
    for bad in ("3", 2.0, True):
        with pytest.raises(TypeError, match="mass_matrix_substeps must be an int"):
            ms2.Ms2Env("PickCube-v0", mass_matrix_substeps=bad)
    # None means the task's default, as for every keyword of the native env.
    none = ms2.Ms2Env("PickCube-v0", mass_matrix_substeps=None)
    assert none.mass_matrix_substeps == DEFAULT_MASS_MATRIX_SUBSTEPS
    for bad in (0, -1, 1001, 2**40):
        expected = rf"mass_matrix_substeps must be in 1\.\.=1000 physics substeps, got {bad}$"
        with pytest.raises(ValueError, match=expected):
            ms2.Ms2Env("PickCube-v0", mass_matrix_substeps=bad)
    default = _native.recorded_env_kwargs("PickCube-v0", {"obs_mode": "state"})
    assert "mass_matrix_substeps" not in default
    one = _native.recorded_env_kwargs(
        "PickCube-v0", {"obs_mode": "state", "mass_matrix_substeps": 1}
    )
    assert one["mass_matrix_substeps"] == 1
    fill = _native.recorded_env_kwargs("Fill-v0", {"obs_mode": "state", "mass_matrix_substeps": 1})
    assert "mass_matrix_substeps" not in fill  # the soft tasks' default

    def run(n):
        e = ms2.Ms2Env("PickCube-v0", obs_mode="state", mass_matrix_substeps=n)
        e.reset(seed=2)
        rng = np.random.default_rng(0)
        for _ in range(20):
            e.step(rng.uniform(-1, 1, e.action_space.shape).astype(np.float32))
        return e.get_state()

    reused, rebuilt = run(DEFAULT_MASS_MATRIX_SUBSTEPS), run(1)
    np.testing.assert_array_equal(reused, run(DEFAULT_MASS_MATRIX_SUBSTEPS))
    assert not np.array_equal(reused, rebuilt)
    assert float(np.abs(reused - rebuilt).max()) < 0.05


def test_filtered_pair_recycling_is_checked_recorded_when_not_default_and_repeatable():
    """Issue #21: ``filtered_pair_recycling`` (ms2's own keyword) must be a number in [0, 1];
    the default agrees with the native one; the resolved value reaches the env's config; a
    trajectory records it only when it is not the default; runs with it off or on repeat."""
    from ms2 import _native
    from ms2.envs import DEFAULT_FILTERED_PAIR_RECYCLING

    env = ms2.Ms2Env("PickCube-v0", obs_mode="state")
    assert env.filtered_pair_recycling == DEFAULT_FILTERED_PAIR_RECYCLING
    assert env._native.config()["filtered_pair_recycling"] == DEFAULT_FILTERED_PAIR_RECYCLING
    off = ms2.Ms2Env("PickCube-v0", obs_mode="state", filtered_pair_recycling=0)
    assert off.filtered_pair_recycling == 0.0
    for bad in ("1", True, [0.5]):
        with pytest.raises(TypeError, match="filtered_pair_recycling must be a real number"):
            ms2.Ms2Env("PickCube-v0", filtered_pair_recycling=bad)
    for bad in (-0.1, 1.5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match=r"filtered_pair_recycling must be a fraction .* got"):
            ms2.Ms2Env("PickCube-v0", filtered_pair_recycling=bad)
    default = _native.recorded_env_kwargs("PickCube-v0", {"obs_mode": "state"})
    assert "filtered_pair_recycling" not in default
    zero = _native.recorded_env_kwargs(
        "PickCube-v0", {"obs_mode": "state", "filtered_pair_recycling": 0.0}
    )
    assert zero["filtered_pair_recycling"] == 0.0

    def run(f):
        e = ms2.Ms2Env("StackCube-v0", obs_mode="state", filtered_pair_recycling=f)
        e.reset(seed=3)
        rng = np.random.default_rng(1)
        for _ in range(20):
            e.step(rng.uniform(-1, 1, e.action_space.shape).astype(np.float32))
        return e.get_state()

    np.testing.assert_array_equal(run(0.0), run(0.0))
    np.testing.assert_array_equal(run(None), run(None))


def test_soak_runs_every_obs_mode_of_a_task_in_worker_processes(capsys):
    """``ms2 bench --soak --jobs 2`` in small: every obs mode of PickCube soaked with resets and
    set_state, no NaN handed out, no errors; image modes get the small soak cameras."""
    from ms2.soak import VISUAL_MODES, plan, run_soak

    assert "image" in VISUAL_MODES
    # A total large enough for PickCube's state pair to outlast an episode (200 steps), so
    # resets happen, however many tasks share it.
    n = 4000
    while True:
        pick = {mode: steps for env_id, mode, steps in plan(n) if env_id == "PickCube-v0"}
        if pick["state"] >= 300:
            break
        n *= 2
    assert pick["state"] > pick["image"] >= 20  # rendering modes get a smaller share
    total = run_soak(n, seed=3, env_ids=["PickCube-v0"], jobs=2)
    modes = {row["obs_mode"] for row in total["rows"]}
    spec = next(s for s in ms2.task_specs() if s["env_id"] == "PickCube-v0")
    assert modes == set(spec["obs_modes"])
    assert total["steps"] == sum(pick.values())
    assert total["non_finite"] == 0 and total["errors"] == 0, total
    assert total["set_states"] > 0 and total["resets"] > 0
    assert "soak:" in capsys.readouterr().out
    with pytest.raises(ValueError, match="jobs must be an int in \\[1, 64\\], got 0"):
        run_soak(10, jobs=0)


def test_soak_restores_only_states_of_the_current_episode():
    """TurnFaucet loads another faucet (maybe with another handle count, so another state
    length) at every reset: the soak's set_state calls restore states of the episode they were
    recorded in, so none is refused over several resets."""
    from ms2.soak import soak_pair

    row = soak_pair("TurnFaucet-v0", "state", 1200, seed=7)
    assert row["resets"] >= 5, row
    assert row["set_states"] > 0, row
    assert row["errors"] == {} and row["non_finite"] == 0, row


def _children(pid: int) -> list[int]:
    """Live (not zombie) processes whose parent is ``pid``, from /proc."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_soak_workers_end_when_the_soak_is_killed():
    """kill -9 of ``ms2 bench --soak --jobs 2`` leaves no worker soaking on alone."""
    import time

    script = "from ms2.soak import run_soak; run_soak(10**7, env_ids=['PickCube-v0'], jobs=2)"
    soak = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        workers: list[int] = []
        while time.monotonic() < deadline:
            workers = [p for p in _children(soak.pid) if p != soak.pid]
            if len(workers) >= 2:
                break
            time.sleep(0.2)
        assert len(workers) >= 2, f"the soak started workers {workers}"
    finally:
        soak.kill()
        soak.wait()
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.2)
    assert not [p for p in workers if _alive(p)], "workers outlived the killed soak"
