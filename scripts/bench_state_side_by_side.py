"""Env steps/s of PickCube-v0, `state` obs, uniform random actions, one env: ms2 or ManiSkill2.

Run it with ms2's Python and with a Python that has mani-skill2==0.5.3 (see docs/benchmarks.md),
alternating, each in a fresh process:

    .venv/bin/python scripts/bench_state_side_by_side.py ms2 pd_joint_delta_pos
    /tmp/peer/ms2/bin/python scripts/bench_state_side_by_side.py maniskill2 pd_joint_delta_pos
"""

import sys
import time

import gymnasium as gym
import numpy as np

which, mode = sys.argv[1], sys.argv[2]
if which == "ms2":
    import ms2  # noqa: F401  (registers ms2's envs)
else:
    import mani_skill2.envs  # noqa: F401  (registers ManiSkill2's envs)
env = gym.make("PickCube-v0", obs_mode="state", control_mode=mode)
rng = np.random.default_rng(0)
env.reset(seed=0)
for _ in range(50):
    env.step(env.action_space.sample())
n = 3000
t = time.perf_counter()
for i in range(n):
    action = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
    _, _, term, trunc, _ = env.step(action)
    if term or trunc:
        env.reset()
dt = time.perf_counter() - t
print(f"{which} {mode} {n / dt:.0f}")
