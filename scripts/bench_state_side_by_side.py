"""Env steps/s of one env (PickCube-v0 unless named), `state` obs, uniform random actions: ms2 or
ManiSkill2.

Run it with ms2's Python and with a Python that has mani-skill2==0.5.3 (see docs/benchmarks.md),
alternating, each in a fresh process:

    .venv/bin/python scripts/bench_state_side_by_side.py ms2 pd_joint_delta_pos
    /tmp/peer/ms2/bin/python scripts/bench_state_side_by_side.py maniskill2 pd_joint_delta_pos
    .venv/bin/python scripts/bench_state_side_by_side.py ms2 pd_ee_delta_pose StackCube-v0
"""

import sys
import time

import gymnasium as gym
import numpy as np

which, mode = sys.argv[1], sys.argv[2]
env_id = sys.argv[3] if len(sys.argv) > 3 else "PickCube-v0"
if which == "ms2":
    import ms2  # noqa: F401  (registers ms2's envs)
else:
    import mani_skill2.envs  # noqa: F401  (registers ManiSkill2's envs)
env = gym.make(env_id, obs_mode="state", control_mode=mode)
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
print(f"{which} {env_id} {mode} {n / dt:.0f}")
