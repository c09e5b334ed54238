"""The task registry seen from Python: specs readable without building an env, gymnasium ids
registered from them, and ManiSkill2's ``robot=`` keyword."""

from __future__ import annotations

import gymnasium as gym
import ms2
import pytest
from conftest import make


def test_specs_describe_every_registered_task():
    specs = {s["env_id"]: s for s in ms2.task_specs()}
    assert set(specs) == set(ms2.env_ids())
    for env_id, spec in specs.items():
        assert gym.spec(env_id).max_episode_steps == spec["max_episode_steps"]
        assert spec["default_control_mode"]
        assert "state" in spec["obs_modes"]
    assert specs["PickCube-v0"]["robots"] == ["panda", "xmate3_robotiq"]
    assert specs["Excavate-v0"]["robots"] == ["panda"]
    assert specs["PandaAvoidObstacles-v0"]["robots"] == ["panda"]
    assert specs["Excavate-v0"]["soft_bodies"] and not specs["PickCube-v0"]["soft_bodies"]


def test_robot_keyword_selects_a_supported_robot():
    env = make("PickCube-v0", robot="panda", obs_mode="state")
    assert env.unwrapped.robot == "panda"
    default = make("PickCube-v0", obs_mode="state")
    assert default.unwrapped.robot == "panda"
    obs, _ = env.reset(seed=0)
    obs_default, _ = default.reset(seed=0)
    assert (obs == obs_default).all()


@pytest.mark.parametrize("robot", ["ur5", "mobile_panda_single_arm"])
def test_unknown_robot_is_a_value_error_listing_the_valid_ones(robot):
    with pytest.raises(ValueError, match=robot) as err:
        make("PickCube-v0", robot=robot)
    assert "panda" in str(err.value)


def test_robot_of_the_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="robot"):
        make("PickCube-v0", robot=3)
