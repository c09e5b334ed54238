"""Trajectories written by the previous main (before the task-runtime reorganisation) replay bit
for bit on this build: from their seeds, and (rigid tasks) from recorded env states. The expected
states were re-recorded when the simulation changed on purpose (the fixture's README says when),
so this guards against every change that was not meant.

The fixture and how it was made: ``fixtures/prev_main/README.md``. It was recorded with ms2's
primitive Panda, so each check runs in a child process with ``MS2_PANDA_DESCRIPTION=primitive``
(the Panda description is chosen once per process, and setup fetches the real one).
"""

from __future__ import annotations

import hashlib
import json
import os
import pathlib
import subprocess
import sys

import h5py
import ms2
import numpy as np
import pytest

FIXTURE = pathlib.Path(__file__).parent / "fixtures" / "prev_main"
EXPECTED = np.load(FIXTURE / "expected_states.npz")
EPISODES = [
    (js.stem, ep["episode_id"])
    for js in sorted(FIXTURE.glob("*.json"))
    for ep in json.loads(js.read_text())["episodes"]
]


def _load(env_id: str, episode_id: int):
    meta = json.loads((FIXTURE / f"{env_id}.json").read_text())
    episode = next(e for e in meta["episodes"] if e["episode_id"] == episode_id)
    with h5py.File(FIXTURE / f"{env_id}.h5") as f:
        group = f[f"traj_{episode_id}"]
        actions = group["actions"][:]
        env_states = group["env_states"][:] if "env_states" in group else None
    return meta["env_info"]["env_kwargs"], episode, actions, env_states


def _digest(state: np.ndarray) -> np.ndarray:
    raw = np.ascontiguousarray(state, dtype=np.float32).tobytes()
    return np.frombuffer(hashlib.sha256(raw).digest(), dtype=np.uint8)


def _in_primitive_panda_process(check: str, env_id: str, episode_id: int) -> None:
    env = {**os.environ, "MS2_PANDA_DESCRIPTION": "primitive"}
    out = subprocess.run(
        [sys.executable, __file__, check, env_id, str(episode_id)],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.parametrize(("env_id", "episode_id"), EPISODES)
def test_replay_from_seed_is_bit_identical(env_id, episode_id):
    _in_primitive_panda_process("seed", env_id, episode_id)


@pytest.mark.parametrize(
    ("env_id", "episode_id"), [e for e in EPISODES if f"{e[0]}/traj_{e[1]}/states" in EXPECTED]
)
def test_replay_with_env_states_is_bit_identical(env_id, episode_id):
    _in_primitive_panda_process("env_states", env_id, episode_id)


def _check_replay_from_seed(env_id, episode_id):
    kwargs, episode, actions, _ = _load(env_id, episode_id)
    digests = EXPECTED[f"{env_id}/traj_{episode_id}/sha256"]
    assert len(digests) == len(actions) + 1
    env = ms2.Ms2Env(env_id, **kwargs)
    env.reset(seed=episode["episode_seed"])
    states = [env.unwrapped.get_state()]
    for action in actions:
        *_, info = env.step(action)
        states.append(env.unwrapped.get_state())
    env.close()
    for t, (state, expected) in enumerate(zip(states, digests, strict=True)):
        assert np.array_equal(_digest(state), expected), f"{env_id} diverges at state {t}"
    final_key = f"{env_id}/traj_{episode_id}/final_state"
    if final_key in EXPECTED.files:
        np.testing.assert_array_equal(states[-1], EXPECTED[final_key])
    assert info["success"] == episode["info"]["success"]


def _check_replay_with_env_states(env_id, episode_id):
    kwargs, _, actions, _ = _load(env_id, episode_id)
    env_states = EXPECTED[f"{env_id}/traj_{episode_id}/states"]
    env = ms2.Ms2Env(env_id, **kwargs)
    env.reset(seed=0)
    for t, action in enumerate(actions):
        env.unwrapped.set_state(env_states[t])
        env.step(action)
        np.testing.assert_array_equal(
            env.unwrapped.get_state(), env_states[t + 1], err_msg=f"{env_id} step {t}"
        )
    env.close()


if __name__ == "__main__":
    check, env_id, episode_id = sys.argv[1], sys.argv[2], int(sys.argv[3])
    from ms2.assets import panda_description

    assert panda_description()["real"] is False, "the fixture needs the primitive Panda"
    {"seed": _check_replay_from_seed, "env_states": _check_replay_with_env_states}[check](
        env_id, episode_id
    )
