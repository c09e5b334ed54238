"""ms2 evaluate: ManiSkill2's submission interface, episode configs, results files, and every
way a solution can fail an episode (recorded with its reason; the run goes on)."""

from __future__ import annotations

import json
import os
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from gymnasium import spaces
from ms2.cli import main
from ms2.evaluation import (
    BasePolicy,
    EpisodeConfig,
    EvaluationConfig,
    RandomPolicy,
    run_evaluation,
)
from ms2.evaluation.config import model_split
from ms2.evaluation.guard import PolicyCaller, PolicyFailure, check_action

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "evaluation"
GOOD_SOLUTION = EXAMPLES / "pickcube_solution.py"
BROKEN_SOLUTION = EXAMPLES / "broken_solution.py"

ZERO_POLICY = """
import numpy as np
from ms2.evaluation.solution import BasePolicy

class UserPolicy(BasePolicy):
    def act(self, observations):
        return np.zeros(self.action_space.shape, dtype=np.float32)

    @classmethod
    def get_obs_mode(cls, env_id):
        return "state"

    @classmethod
    def get_control_mode(cls, env_id):
        return "pd_ee_delta_pose"
"""


def write(path: Path, text: str) -> Path:
    path.write_text(textwrap.dedent(text))
    return path


def evaluate_cli(capsys, *args: str) -> tuple[int, str, str]:
    code = main(["evaluate", "-q", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def read_json(path: Path):
    return json.loads(path.read_text())


def test_good_solution_succeeds_and_writes_maniskill2_results(tmp_path, capsys):
    out_dir = tmp_path / "results"
    code, out, _ = evaluate_cli(
        capsys, "--env-id", "PickCube-v0", "--solution", GOOD_SOLUTION, "-n", 3, "-o", out_dir
    )
    assert code == 0
    assert "success rate 3/3 = 100.0 %" in out
    assert sorted(p.name for p in out_dir.iterdir()) == [
        "average_metrics.json",
        "episode_results.json",
        "results.json",
    ]  # no temporary files left behind
    per_episode = read_json(out_dir / "episode_results.json")
    assert list(per_episode) == ["0", "1", "2"]
    keys = set(per_episode["0"])
    assert {"elapsed_steps", "success", "is_obj_placed", "failed"} <= keys
    for metrics in per_episode.values():
        assert set(metrics) == keys and metrics["success"] == 1.0 and metrics["failed"] == 0.0
        assert 1 <= metrics["elapsed_steps"] < 200  # ended by success, before the time limit
    average = read_json(out_dir / "average_metrics.json")
    assert average["success"] == 1.0
    assert average["elapsed_steps"] == pytest.approx(
        np.mean([m["elapsed_steps"] for m in per_episode.values()])
    )
    summary = read_json(out_dir / "results.json")
    assert summary["solution"] == "pickcube_solution"
    assert (summary["obs_mode"], summary["control_mode"]) == ("state_dict", "pd_ee_delta_pos")
    assert summary["model_split"] is None  # PickCube has no asset models
    assert [e["seed"] for e in summary["episodes"]] == [0, 1, 2]
    assert summary["num_successes"] == 3 and summary["num_failed"] == 0


def test_broken_solution_reports_every_failure_mode_and_completes(tmp_path, capsys):
    out_dir = tmp_path / "broken"
    started = time.perf_counter()
    code, out, _ = evaluate_cli(
        capsys,
        *("--env-id", "PickCube-v0", "--solution", BROKEN_SOLUTION, "-n", 9),
        *("--step-time-limit", 0.5, "-o", out_dir),
    )
    assert code == 0
    # The hung call was abandoned, not waited for (it sleeps 2 s).
    assert time.perf_counter() - started < 2 + 0.5 + 10
    summary = read_json(out_dir / "results.json")
    episodes = summary["episodes"]
    assert len(episodes) == 9
    expected = [
        (None, None, None),
        ("exception", 2, "act(obs) raised RuntimeError: the network diverged"),
        ("non_finite_action", 2, "non-finite action: nan at index 0, inf at index 1"),
        ("invalid_action", 2, "shape (8,), expected (7,)"),
        ("invalid_action", 2, "returned str of dtype <U9; expected real numbers"),
        ("invalid_action", 2, "act() returned None"),
        ("timeout", 2, "did not return within the per-step time limit of 0.5 s"),
        ("exception", 0, "reset(obs) raised KeyError: \"no such checkpoint: 'policy.pt'\""),
        (None, None, None),  # a fresh policy object after the timeout works again
    ]
    for episode, (kind, step, reason) in zip(episodes, expected, strict=True):
        failure = episode["failure"]
        if kind is None:
            assert failure is None, episode
            assert episode["elapsed_steps"] == 200  # zero actions until the time limit
            continue
        assert failure["kind"] == kind and failure["step"] == step, episode
        assert reason in failure["reason"], failure
        assert reason in out  # the command line lists every failure
        assert not episode["success"]
    assert summary["num_failed"] == 7
    assert summary["failures_by_kind"] == {
        "exception": 2,
        "non_finite_action": 1,
        "invalid_action": 3,
        "timeout": 1,
    }
    assert summary["abandoned_calls"] == 1
    per_episode = read_json(out_dir / "episode_results.json")
    assert [m["failed"] for m in per_episode.values()] == [0, 1, 1, 1, 1, 1, 1, 1, 0]
    assert len({tuple(m) for m in per_episode.values()}) == 1  # same keys everywhere


def test_config_file_selects_episodes_env_kwargs_and_count(tmp_path, capsys):
    solution = write(tmp_path / "user_solution.py", ZERO_POLICY)
    config = {
        "env_info": {"env_id": "PickCube-v0", "env_kwargs": {"max_episode_steps": 7}},
        "episodes": [
            {"episode_id": "first", "reset_kwargs": {"seed": 11}},
            {"episode_id": "second", "reset_kwargs": {"seed": 12}},
            {"episode_id": "third"},
        ],
    }
    config_path = tmp_path / "episodes.json"
    config_path.write_text(json.dumps(config))
    out_dir = tmp_path / "out"
    code, _, _ = evaluate_cli(
        capsys,
        *("-e", "PickCube-v0", "--solution", solution, "--config", config_path),
        *("--num-episodes", 2, "-o", out_dir),
    )
    assert code == 0
    summary = read_json(out_dir / "results.json")
    assert [(e["episode_id"], e["seed"]) for e in summary["episodes"]] == [
        ("first", 11),
        ("second", 12),
    ]
    assert [e["elapsed_steps"] for e in summary["episodes"]] == [7, 7]
    assert summary["env_kwargs"] == {"max_episode_steps": 7}
    assert list(read_json(out_dir / "episode_results.json")) == ["first", "second"]


class _OutOfBounds(BasePolicy):
    def act(self, observations):
        return np.full(self.action_space.shape, 5.0)  # float64, far outside [-1, 1]

    @classmethod
    def get_obs_mode(cls, env_id):
        return "state"

    @classmethod
    def get_control_mode(cls, env_id):
        return None


def test_out_of_bounds_actions_pass_as_in_maniskill2(tmp_path):
    config = EvaluationConfig(
        "PickCube-v0", {"max_episode_steps": 3}, [EpisodeConfig(0, {"seed": 0})]
    )
    summary = run_evaluation("PickCube-v0", _OutOfBounds, tmp_path, config=config)
    assert summary["num_failed"] == 0 and summary["episodes"][0]["elapsed_steps"] == 3
    assert summary["solution"] == "_OutOfBounds"
    assert summary["control_mode"] == "pd_joint_delta_pos"  # None: the task's default


def _policy_file(tmp_path: Path, body: str) -> Path:
    return write(tmp_path / "user_solution.py", body)


@pytest.mark.parametrize(
    ("make_args", "message"),
    [
        (lambda p: ["-e", "NoSuchTask-v0", "--solution", GOOD_SOLUTION], "unknown env id"),
        (
            lambda p: ["-e", "PickCube-v0", "--solution", p / "missing.py"],
            "missing.py does not exist",
        ),
        (
            lambda p: ["-e", "PickCube-v0", "--solution", _policy_file(p, "import no_such_mod\n")],
            "failed at line 1: ModuleNotFoundError: No module named 'no_such_mod'",
        ),
        (
            lambda p: ["-e", "PickCube-v0", "--solution", _policy_file(p, "x = 1\ndef (:\n")],
            "failed at line 2: SyntaxError",
        ),
        (
            lambda p: ["-e", "PickCube-v0", "--solution", _policy_file(p, "Policy = 1\n")],
            "defines no UserPolicy",
        ),
        (
            lambda p: [
                *("-e", "PickCube-v0", "--solution"),
                _policy_file(p, ZERO_POLICY.replace('return "state"', 'return "nonsense"')),
            ],
            "cannot make PickCube-v0 with obs_mode='nonsense'",
        ),
        (
            lambda p: [
                *("-e", "PickCube-v0", "--solution"),
                _policy_file(
                    p,
                    ZERO_POLICY
                    + "    def __init__(self, *args):\n        raise OSError('no weights')\n",
                ),
            ],
            "UserPolicy('PickCube-v0', observation_space, action_space) raised OSError: no weights",
        ),
    ],
    ids=[
        "bad-env-id",
        "missing-file",
        "import-error",
        "syntax-error",
        "no-class",
        "bad-mode",
        "constructor-raises",
    ],
)
def test_unusable_solution_or_task_is_a_clear_error(tmp_path, capsys, make_args, message):
    out_dir = tmp_path / "out"
    code, out, err = evaluate_cli(capsys, *make_args(tmp_path), "-o", out_dir)
    assert code == 2
    assert message in err and "Traceback" not in err
    assert message in (out_dir / "error.log").read_text()  # as ManiSkill2's error.log
    assert not (out_dir / "results.json").exists()


@pytest.mark.parametrize(
    ("config", "message"),
    [
        ("{not json", "is not valid JSON"),
        ("[1, 2]", "expected a JSON object with env_info and episodes"),
        ({"env_info": {"env_id": "StackCube-v0"}, "episodes": [{}]}, "env_id is 'StackCube-v0'"),
        ({"env_info": {"env_id": "PickCube-v0"}, "episodes": []}, "non-empty list"),
        (
            {
                "env_info": {"env_id": "PickCube-v0", "env_kwargs": {"obs_mode": "rgbd"}},
                "episodes": [{}],
            },
            "may not set 'obs_mode'",
        ),
        (
            {
                "env_info": {"env_id": "PickCube-v0"},
                "episodes": [{"episode_id": 3}, {"episode_id": 3}],
            },
            "episodes[1]: episode_id 3 is not unique",
        ),
        (
            {"env_info": {"env_id": "PickCube-v0"}, "episodes": [{"reset_kwargs": {"seed": -1}}]},
            "episodes[0].reset_kwargs.seed must be an int >= 0",
        ),
        (
            {"env_info": {"env_id": "PickCube-v0"}, "episodes": [{"reset_kwargs": {"sed": 1}}]},
            "unknown key(s) ['sed']",
        ),
    ],
    ids=[
        "not-json",
        "not-object",
        "other-task",
        "no-episodes",
        "obs-mode",
        "duplicate-id",
        "negative-seed",
        "unknown-key",
    ],
)
def test_malformed_config_is_a_clear_error(tmp_path, capsys, config, message):
    solution = write(tmp_path / "user_solution.py", ZERO_POLICY)
    path = tmp_path / "episodes.json"
    path.write_text(config if isinstance(config, str) else json.dumps(config))
    code, _, err = evaluate_cli(
        capsys, "-e", "PickCube-v0", "--solution", solution, "--config", path, "-o", tmp_path / "o"
    )
    assert code == 2
    assert message in err and str(path) in err


def test_bad_reset_option_fails_only_that_episode(tmp_path):
    config = EvaluationConfig(
        "PickCube-v0",
        {"max_episode_steps": 2},
        [
            EpisodeConfig("bad", {"seed": 0, "options": {"no_such_option": 1}}),
            EpisodeConfig("good", {"seed": 1}),
        ],
    )
    summary = run_evaluation("PickCube-v0", RandomPolicy, tmp_path, config=config)
    bad, good = summary["episodes"]
    assert bad["failure"]["kind"] == "env_error" and "no_such_option" in bad["failure"]["reason"]
    assert (bad["seed"], bad["elapsed_steps"]) == (0, 0)
    assert good["failure"] is None and good["elapsed_steps"] == 2
    per_episode = read_json(tmp_path / "episode_results.json")
    assert set(per_episode["bad"]) == set(per_episode["good"])  # keys filled in


def test_record_dir_writes_a_video_per_episode(tmp_path, capsys):
    pytest.importorskip("imageio_ffmpeg")
    solution = write(tmp_path / "user_solution.py", ZERO_POLICY)
    config = tmp_path / "episodes.json"
    config.write_text(
        json.dumps(
            {
                "env_info": {"env_id": "PickCube-v0", "env_kwargs": {"max_episode_steps": 3}},
                "episodes": [{"reset_kwargs": {"seed": 0}}, {"reset_kwargs": {"seed": 1}}],
            }
        )
    )
    out_dir = tmp_path / "out"
    code, _, _ = evaluate_cli(
        capsys,
        *("-e", "PickCube-v0", "--solution", solution, "--config", config),
        *("-o", out_dir, "--record-dir", "@"),
    )
    assert code == 0
    videos = [e["video"] for e in read_json(out_dir / "results.json")["episodes"]]
    assert videos == [str(out_dir / "episode_0.mp4"), str(out_dir / "episode_1.mp4")]
    assert all(Path(v).stat().st_size > 0 for v in videos)
    assert (out_dir / "trajectory.h5").exists() and (out_dir / "trajectory.json").exists()
    assert len(read_json(out_dir / "trajectory.json")["episodes"]) == 2


def test_test_split_draws_held_out_models_and_restores_the_variable(tmp_path, monkeypatch):
    monkeypatch.delenv("MS2_FAUCET_MODELS", raising=False)
    episodes = [EpisodeConfig(i, {"seed": i}) for i in range(4)]
    config = EvaluationConfig("TurnFaucet-v0", {"max_episode_steps": 1}, episodes)
    models = {}
    for split in ("test", "train"):
        summary = run_evaluation(
            "TurnFaucet-v0", RandomPolicy, tmp_path / split, config=config, split=split
        )
        assert summary["model_split"] == split
        models[split] = {e["model_id"] for e in summary["episodes"]}
        assert None not in models[split]
    assert not models["test"] & models["train"]
    assert "MS2_FAUCET_MODELS" not in os.environ
    with pytest.raises(ValueError, match="model split must be one of"):
        with model_split("TurnFaucet-v0", "validation"):
            pass


def test_check_action():
    space = spaces.Box(-1.0, 1.0, (3,), np.float32)
    ok = check_action([1, 2, 3], space)
    assert ok.dtype == np.float32 and ok.tolist() == [1.0, 2.0, 3.0]
    cases = [
        (np.zeros((1, 3)), "invalid_action", "shape (1, 3), expected (3,)"),
        (np.zeros(3, dtype=complex), "invalid_action", "dtype complex128"),
        ({"a": 1}, "invalid_action", "dict of dtype object"),
        (np.array([0.0, 1e300, 0.0]), "non_finite_action", "inf at index 1"),
        (np.array([np.nan] * 5)[:3], "non_finite_action", "nan at index 0"),
    ]
    for action, kind, reason in cases:
        with pytest.raises(PolicyFailure) as info:
            check_action(action, space)
        assert info.value.kind == kind and reason in info.value.reason


def test_policy_caller_time_limit_abandons_and_recovers():
    caller = PolicyCaller(0.2)
    assert caller.call("act(obs)", lambda x: x + 1, 1) == 2
    with pytest.raises(PolicyFailure) as info:
        caller.call("act(obs)", time.sleep, 1.0)
    assert info.value.kind == "timeout" and "0.2 s" in info.value.reason
    assert caller.abandoned == 1
    assert caller.call("act(obs)", lambda: "fresh worker") == "fresh worker"
    with pytest.raises(PolicyFailure, match=r"act\(obs\) raised ZeroDivisionError"):
        caller.call("act(obs)", lambda: 1 / 0)
    caller.close()
    direct = PolicyCaller(None)
    with pytest.raises(PolicyFailure, match="SystemExit"):
        direct.call("reset(obs)", lambda: exit(3))
    for bad in (0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="positive number of seconds"):
            PolicyCaller(bad)
    with pytest.raises(TypeError):
        PolicyCaller("10")


def test_base_policy_interface():
    obs_space = spaces.Box(-1, 1, (2,))
    act_space = spaces.Box(-1, 1, (4,))
    policy = BasePolicy("PickCube-v0", obs_space, act_space)
    assert (policy.env_id, policy.observation_space, policy.action_space) == (
        "PickCube-v0",
        obs_space,
        act_space,
    )
    assert policy.reset(None) is None
    for call in (lambda: policy.act(None), lambda: BasePolicy.get_obs_mode("PickCube-v0")):
        with pytest.raises(NotImplementedError):
            call()


def test_step_time_limit_option_is_checked(capsys):
    with pytest.raises(SystemExit) as info:
        main(
            [
                "evaluate",
                "-e",
                "PickCube-v0",
                "--solution",
                "x.py",
                "-o",
                "o",
                "--step-time-limit",
                "-1",
            ]
        )
    assert info.value.code == 2
    assert "expected a positive number of seconds, got '-1'" in capsys.readouterr().err


class _HangsThenCannotRebuild(BasePolicy):
    """Hangs in its first act(); every policy object after the first fails to build."""

    built = 0

    def __init__(self, *args):
        type(self).built += 1
        if type(self).built > 1:
            raise MemoryError("out of GPU memory")
        super().__init__(*args)

    def act(self, observations):
        time.sleep(1.0)
        return np.zeros(self.action_space.shape)

    @classmethod
    def get_obs_mode(cls, env_id):
        return "state"

    @classmethod
    def get_control_mode(cls, env_id):
        return None


def test_policy_rebuilt_after_a_timeout_and_its_failure_recorded(tmp_path):
    episodes = [EpisodeConfig(i, {"seed": 10 + i}) for i in range(3)]
    config = EvaluationConfig("PickCube-v0", {"max_episode_steps": 2}, episodes)
    summary = run_evaluation(
        "PickCube-v0", _HangsThenCannotRebuild, tmp_path, config=config, step_time_limit=0.2
    )
    kinds = [e["failure"]["kind"] for e in summary["episodes"]]
    assert kinds == ["timeout", "exception", "exception"]
    for episode in summary["episodes"][1:]:
        assert (
            "_HangsThenCannotRebuild('PickCube-v0', observation_space, action_space) raised "
            "MemoryError: out of GPU memory" in episode["failure"]["reason"]
        )
    assert [e["seed"] for e in summary["episodes"]] == [10, 11, 12]
    assert _HangsThenCannotRebuild.built == 3  # one try per episode after the timeout
