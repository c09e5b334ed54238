"""The scripted (oracle) policies solve their tasks through the gymnasium API."""

from __future__ import annotations

import ms2
import pytest
from conftest import HEAVY, MAIN_ID, make, preferred_control_mode

#: Episodes per task; the success-rate floor leaves room for the odd hard initial state.
EPISODES = 10
#: Soft-body tasks (MPM) are ~50x slower per step, and an episode of Write-v0 (17,640
#: particles), Pour-v0 (10,548 water particles) or Hang-v0 (its rope at 4 kHz) takes minutes: one
#: episode each (seed 0, a success in their sweeps) unless MS2_HEAVY_TESTS=1, then five
#: (Write-v0, Pour-v0 and Hang-v0 two). Their
#: rates over seeds 0-49 come from the Rust examples `scripted_rates` / `soft_env_rates`
#: (docs/tasks.md).
SOFT_EPISODES = 5 if HEAVY else 1
EPISODES_OF = {"Write-v0": 2, "Pour-v0": 2, "Hang-v0": 2} if HEAVY else {}
MIN_SUCCESS_RATE = 0.8
#: Tasks whose scripted policy is measured in another mode than the preferred one: the
#: obstacle reach replays a joint-space plan (pd_ee_delta_pose: 23/30, docs/tasks.md).
SCRIPTED_MODE = {"PandaAvoidObstacles-v0": "pd_joint_delta_pos"}
#: Known failures, documented in docs/tasks.md: PickSingleYCB-v0 (6/10 on seeds 0-9 since
#: every reset rebuilds the scene: wide bowls, long tools; issue #16), PickClutterYCB-v0
#: (20/30 on seeds 0-29 in pd_ee_delta_pose: neighbours in the way of its top-down grasp;
#: issue #16).
KNOWN_FAILING = {"PickSingleYCB-v0", "PickClutterYCB-v0"}
#: Solved but too slow for this suite, measured with the Rust examples instead (docs/tasks.md).
#: Empty since Pour-v0's coupling got cheaper (issue #20: about half its step's CPU).
TOO_SLOW_HERE: dict[str, str] = {}


def test_scripted_policy_success_rate(env_id):
    if env_id in KNOWN_FAILING:
        pytest.xfail(f"{env_id}: scripted policy below the floor (docs/tasks.md, known problem)")
    if env_id in TOO_SLOW_HERE:
        pytest.skip(f"{env_id}: {TOO_SLOW_HERE[env_id]}")
    soft = "particles" in ms2.Ms2Env(env_id).supported_obs_modes
    # The soft-body solutions are tuned in their envs' default pd_joint_delta_pos (they also
    # succeed in pd_ee_delta_pose: docs/tasks.md).
    mode = None if soft else SCRIPTED_MODE.get(env_id, preferred_control_mode(env_id))
    env = make(env_id, obs_mode="state", control_mode=mode)
    policy = ms2.ScriptedPolicy(env)
    episodes = EPISODES_OF.get(env_id, SOFT_EPISODES if soft else EPISODES)
    successes = 0
    for seed in range(episodes):
        env.reset(seed=seed)
        policy.reset()
        while True:
            _, _, terminated, truncated, info = env.step(policy.act())
            if terminated or truncated:
                break
        successes += bool(info["success"])
    assert successes / episodes >= MIN_SUCCESS_RATE, f"{env_id}: {successes}/{episodes}"


def test_random_policy_rarely_succeeds():
    env = make(MAIN_ID, obs_mode="state", control_mode=preferred_control_mode(MAIN_ID))
    successes = 0
    for seed in range(3):
        env.reset(seed=seed)
        env.action_space.seed(seed)
        while True:
            _, _, terminated, truncated, info = env.step(env.action_space.sample())
            if terminated or truncated:
                break
        successes += bool(info["success"])
    assert successes == 0


def test_scripted_policy_needs_an_ms2_env():
    import gymnasium as gym

    with pytest.raises(TypeError, match="ms2 env"):
        ms2.ScriptedPolicy(gym.make("CartPole-v1"))


def test_liftcube_normalized_dense_reward_along_a_scripted_lift():
    """LiftCube-v0's ``normalized_dense`` reward (ManiSkill2's terms over 2.25) along the scripted
    grasp and lift in ``pd_ee_delta_pose``: reach only while the cube is on the table (at most
    (1 + 0.25) / 2.25 < 0.56), reach + grasp + lift fraction once it is half lifted (> 0.7),
    within [0, 1] throughout, and exactly 1 at the success that ends the episode."""
    env = make("LiftCube-v0", obs_mode="state_dict", control_mode="pd_ee_delta_pose",
               reward_mode="normalized_dense")  # fmt: skip
    policy = ms2.ScriptedPolicy(env)
    for seed in range(2):
        env.reset(seed=seed)
        policy.reset()
        on_table, half_lifted = [], []
        while True:
            obs, reward, terminated, truncated, info = env.step(policy.act())
            assert 0.0 <= reward <= 1.0
            cube_z = obs["extra"]["obj_pose"][2]  # cube centre height (m); half size 0.02
            if cube_z < 0.021:
                on_table.append(reward)
            elif cube_z - 0.02 >= 0.1 and not info["success"]:
                half_lifted.append(reward)
            if terminated or truncated:
                break
        assert info["success"] and reward == pytest.approx(1.0, abs=1e-6)
        assert on_table and max(on_table) < 0.56, on_table
        assert half_lifted and min(half_lifted) > 0.7, half_lifted
