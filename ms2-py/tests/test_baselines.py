"""Smoke tests of examples/baselines/ (PPO and behaviour cloning) and of SB3VecEnvWrapper under
real stable-baselines3. Run only where the ``baselines`` extra (torch, stable-baselines3) is
installed; each script runs end to end with tiny settings (a few hundred env steps)."""

from __future__ import annotations

import csv
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")

import ms2  # noqa: E402
import torch  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "baselines"


@pytest.fixture(autouse=True)
def _one_torch_thread():
    before = torch.get_num_threads()
    yield
    torch.set_num_threads(before)


def load_example(name: str):
    spec = importlib.util.spec_from_file_location(f"baselines_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("backend", ["ms2", "gym"])
def test_ppo_state_runs_end_to_end(tmp_path, backend):
    ppo = load_example("ppo_state")
    out = tmp_path / "ppo"
    summary = ppo.main(
        ["--env", "LiftCube-v0", "--backend", backend, "--num-envs", "2",
         "--max-episode-steps", "20", "--total-steps", "400", "--rollout-steps", "200",
         "--batch-size", "50", "--n-epochs", "1", "--eval-freq", "200",
         "--eval-episodes", "2", "--out", str(out)]
    )  # fmt: skip
    assert (out / "model.zip").stat().st_size > 0
    rows = read_csv(out / "eval.csv")
    assert [int(r["env_steps"]) for r in rows] == [0, 200, 400]
    walls = [float(r["wall_s"]) for r in rows]
    assert walls == sorted(walls)
    for r in rows:
        assert 0.0 <= float(r["success_rate"]) <= 1.0
        assert int(r["eval_episodes"]) == 2
        assert 0.0 <= float(r["train_success_rate"]) <= 1.0
    # 200 steps over 2 envs with a 20-step limit: 10 training episodes end between evaluations.
    assert [int(r["train_episodes"]) for r in rows] == [0, 10, 10]
    assert json.loads((out / "summary.json").read_text()) == summary
    assert summary["env_steps"] == 400
    # The saved model loads and acts in the task's action space.
    from stable_baselines3 import PPO

    model = PPO.load(out / "model.zip", device="cpu")
    action, _ = model.predict(np.zeros(model.observation_space.shape, np.float32))
    assert action.shape == (7,)


def test_ppo_state_time_limit_stops_training_and_evaluates(tmp_path):
    """``--time-limit 0`` stops training at its first env step (one step of each env), then the
    final evaluation runs and the model and summary are written."""
    ppo = load_example("ppo_state")
    out = tmp_path / "ppo"
    summary = ppo.main(
        ["--env", "LiftCube-v0", "--num-envs", "2", "--max-episode-steps", "20",
         "--total-steps", "400", "--rollout-steps", "200", "--batch-size", "50",
         "--n-epochs", "1", "--eval-freq", "200", "--eval-episodes", "2",
         "--eval-max-episode-steps", "5", "--time-limit", "0", "--out", str(out)]
    )  # fmt: skip
    assert summary["env_steps"] == 2
    assert [int(r["env_steps"]) for r in read_csv(out / "eval.csv")] == [0, 2]
    assert (out / "model.zip").stat().st_size > 0


def test_ppo_continuous_vec_env_reports_success_as_truncation(tmp_path):
    """A demo's actions replayed in the training env: the success that ends the native episode
    is reported as a time-limit truncation (PPO bootstraps), the plain wrapper's as a
    termination."""
    import h5py
    from ms2.cli import main as cli_main
    from ms2.wrappers import SB3VecEnvWrapper

    demos = tmp_path / "demo.h5"
    cli_main(["demos", "generate", "PickCube-v0", "-n", "1", "--policy", "scripted",
                  "-c", "pd_ee_delta_pose", "--out", str(demos), "-q"])  # fmt: skip
    with h5py.File(demos, "r") as f:
        actions = np.asarray(f["traj_0"]["actions"])
    ppo = load_example("ppo_state")
    kwargs = dict(obs_mode="state", control_mode="pd_ee_delta_pose")
    for cls, truncated in [(ppo.make_continuous_vec_env_class(), True), (SB3VecEnvWrapper, False)]:
        venv = cls(ms2.make_vec("PickCube-v0", num_envs=1, **kwargs))
        venv.seed(0)
        venv.reset()
        for t, action in enumerate(actions):
            _, _, dones, infos = venv.step(action[None])
            assert dones[0] == (t == len(actions) - 1)
        assert infos[0]["success"] and "terminal_observation" in infos[0]
        assert infos[0]["TimeLimit.truncated"] is truncated
        if truncated:
            assert infos[0]["is_success"] is True
        venv.close()


def test_bc_state_runs_end_to_end(tmp_path):
    bc = load_example("bc_state")
    out = tmp_path / "bc"
    summary = bc.main(
        ["--env", "PickCube-v0", "--num-demos", "3", "--steps", "50", "--eval-episodes", "2",
         "--eval-envs", "2", "--max-episode-steps", "30", "--out", str(out)]
    )  # fmt: skip
    assert (out / "model.pt").stat().st_size > 0
    assert (out / "demos.state.pd_ee_delta_pose.h5").exists()
    assert json.loads((out / "summary.json").read_text()) == summary
    assert 0.0 <= summary["success_rate"] <= 1.0
    assert summary["num_demos"] == 3 and summary["steps"] == 50 and summary["pairs"] > 3
    # Reading existing demos (--demos): fewer trajectories than asked is an error.
    with pytest.raises(SystemExit, match="fewer than 5"):
        bc.main(["--demos", str(out / "demos.state.pd_ee_delta_pose.h5"), "--num-demos", "5",
                 "--out", str(tmp_path / "bc2")])  # fmt: skip
    # The saved weights load into the script's policy and give actions in [-1, 1].
    obs, actions = bc.load_demos(out / "demos.state.pd_ee_delta_pose.h5", 3)
    assert len(obs) == len(actions) == summary["pairs"]
    policy = bc.make_policy(obs.shape[1], actions.shape[1])
    policy.load_state_dict(torch.load(out / "model.pt"))
    with torch.no_grad():
        pred = policy(torch.from_numpy(obs)).numpy()
    assert pred.shape == actions.shape and np.abs(pred).max() <= 1.0


def test_bc_rgbd_runs_end_to_end(tmp_path):
    bc = load_example("bc_rgbd")
    out = tmp_path / "bc_rgbd"
    summary = bc.main(
        ["--env", "LiftCube-v0", "--num-demos", "2", "--steps", "5", "--batch-size", "8",
         "--eval-episodes", "1", "--eval-envs", "1", "--max-episode-steps", "10",
         "--out", str(out)]
    )  # fmt: skip
    assert (out / "model.pt").stat().st_size > 0
    assert json.loads((out / "summary.json").read_text()) == summary
    assert 0.0 <= summary["success_rate"] <= 1.0
    assert summary["image_hw"] == [64, 64] and summary["pairs"] > 2
    images, state, actions = bc.load_demos(out / "demos.rgbd.pd_ee_delta_pose.h5", 2)
    assert images.shape == (summary["pairs"], 8, 64, 64) and len(state) == len(actions)
    assert 0.0 <= float(images.min()) and float(images.max()) <= bc.MAX_DEPTH
    policy = bc.make_policy(state.shape[1], actions.shape[1])
    policy.load_state_dict(torch.load(out / "model.pt"))
    with torch.no_grad():
        pred = policy(torch.from_numpy(images[:4]).float(), torch.from_numpy(state[:4]))
    assert pred.shape == (4, 7)


def test_sb3_vec_env_wrapper_with_sb3_tools():
    """SB3VecEnvWrapper under stable-baselines3's own VecMonitor, PPO.learn and
    evaluate_policy (episode counts and lengths as the time limit sets them)."""
    from ms2.wrappers import SB3VecEnvWrapper
    from stable_baselines3 import PPO
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import VecMonitor

    venv = VecMonitor(
        SB3VecEnvWrapper(
            ms2.make_vec("LiftCube-v0", num_envs=2, obs_mode="state", max_episode_steps=16)
        )
    )
    model = PPO("MlpPolicy", venv, n_steps=32, batch_size=32, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=128)
    assert model.num_timesteps == 128
    # 128 steps over 2 envs with a 16-step limit: 8 finished episodes of length 16 each.
    assert len(model.ep_info_buffer) == 8
    assert all(info["l"] == 16 for info in model.ep_info_buffer)
    returns, lengths = evaluate_policy(model, venv, n_eval_episodes=4, return_episode_rewards=True)
    assert len(returns) == 4 and all(length == 16 for length in lengths)
    venv.close()
