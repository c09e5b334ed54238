"""ManiSkill2 0.5.3 measured beside ms2 in ``ms2 bench``: the same loop (pre-drawn uniform
random actions, episodes reset inside the timed loop) run by a Python that has
``mani-skill2==0.5.3`` installed (``--peer-python``), each configuration in a fresh process,
interleaved with ms2's rows so both see the same machine load.

The peer's environment is this process's environment: for SAPIEN 2.2 on Mesa's lavapipe set
``VK_LAYER_PATH`` / ``VK_INSTANCE_LAYERS`` as ``../shared/spec/README.md`` describes.
"""

from __future__ import annotations

import json
import subprocess

#: The loop the peer Python runs: argv[1] is the spec (env_id, obs_mode, control_mode, steps).
_PEER_SCRIPT = r"""
import json, resource, sys, time
import numpy as np
import gymnasium as gym
import mani_skill2.envs  # registers the ManiSkill2 ids

spec = json.loads(sys.argv[1])
env = gym.make(spec["env_id"], obs_mode=spec["obs_mode"], control_mode=spec["control_mode"])
space = env.action_space
rng = np.random.default_rng(1)
actions = rng.uniform(space.low, space.high, size=(1024, *space.low.shape)).astype(np.float32)
env.reset(seed=0)
for i in range(10):
    env.step(actions[i])
env.reset(seed=1)
usage = resource.getrusage(resource.RUSAGE_SELF)
cpu0 = usage.ru_utime + usage.ru_stime
t0 = time.perf_counter()
for i in range(spec["steps"]):
    _, _, terminated, truncated, _ = env.step(actions[i % len(actions)])
    if terminated or truncated:
        env.reset()
elapsed = time.perf_counter() - t0
usage = resource.getrusage(resource.RUSAGE_SELF)
cpu = usage.ru_utime + usage.ru_stime - cpu0
print(json.dumps({
    "steps_per_s": spec["steps"] / elapsed,
    "seconds": elapsed,
    "cpu_ms_per_step": 1e3 * cpu / spec["steps"],
    "env_steps": spec["steps"],
    "peak_rss_mb": usage.ru_maxrss / 1024.0,
    "triangles_per_camera": None,
}))
"""


def run_peer(python: str, spec: dict) -> dict:
    """Runs one single-env configuration (``env_id``, ``obs_mode``, ``control_mode``,
    ``steps``) of ManiSkill2 0.5.3 with ``python`` in a fresh process and returns its result
    (``steps_per_s``, ``cpu_ms_per_step``, ``peak_rss_mb``, ...). Raises ``RuntimeError`` with
    the peer's error output when it fails."""
    out = subprocess.run(
        [python, "-c", _PEER_SCRIPT, json.dumps(spec)],
        capture_output=True,
        text=True,
    )
    if out.returncode != 0:
        tail = "\n".join(out.stderr.strip().splitlines()[-5:])
        raise RuntimeError(f"ManiSkill2 peer run {spec} with {python} failed:\n{tail}")
    return json.loads(out.stdout.strip().splitlines()[-1])
