"""Quick start: one PickCube episode solved by the scripted policy, then a random rollout in a
vector env.  Run with ``python ms2-py/examples/quickstart.py`` after ``./scripts/setup.sh``."""

import gymnasium as gym
import ms2
import numpy as np

env = gym.make("PickCube-v0", obs_mode="state", control_mode="pd_ee_delta_pose")
obs, info = env.reset(seed=0)
print("observation", obs.shape, obs.dtype, "action space", env.action_space)

policy = ms2.ScriptedPolicy(env)
policy.reset()
while True:
    obs, reward, terminated, truncated, info = env.step(policy.act())
    if terminated or truncated:
        break
print(f"scripted episode: success={info['success']} after {info['elapsed_steps']} steps")

# Eight envs stepped in parallel in native threads; finished episodes reset on the next step.
envs = ms2.make_vec("PickCube-v0", num_envs=8, obs_mode="state", control_mode="pd_ee_delta_pose")
obs, info = envs.reset(seed=0)
returns = np.zeros(envs.num_envs)
for _ in range(50):
    obs, rewards, terminated, truncated, info = envs.step(envs.action_space.sample())
    returns += rewards
print("batched observation", obs.shape, "mean return of 50 random steps", returns.mean())
