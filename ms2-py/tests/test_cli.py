"""The ``ms2`` command line."""

from __future__ import annotations

import re
import subprocess
import sys

from conftest import ENV_IDS, MAIN_ID
from ms2.cli import main


def test_envs_lists_tasks(capsys):
    assert main(["envs"]) == 0
    assert capsys.readouterr().out.split() == ENV_IDS


def test_run_scripted_prints_success_rate_and_speed(capsys):
    assert main(["run", MAIN_ID, "--policy", "scripted", "--episodes", "2"]) == 0
    out = capsys.readouterr().out
    m = re.search(
        r"success rate (\d+)/2 = ([\d.]+) %, (\d+) env steps in [\d.]+ s = (\d+) steps/s", out
    )
    assert m, out
    assert int(m.group(1)) >= 1
    assert int(m.group(3)) > 0 and int(m.group(4)) > 0


def test_run_random_and_bad_env(capsys):
    assert "Dummy-v0" not in ENV_IDS  # a test env: not listed
    assert main(["run", MAIN_ID, "--policy", "random", "--episodes", "1"]) == 0
    assert "success rate 0/1" in capsys.readouterr().out
    assert main(["run", "NoSuchEnv-v0", "--episodes", "1"]) == 2
    assert MAIN_ID in capsys.readouterr().err


def _bench_stdout(*args: str) -> str:
    """The stdout of ``python -m ms2 bench *args`` (which must exit 0)."""
    return subprocess.run(
        [sys.executable, "-m", "ms2", "bench", *args],
        check=True,
        capture_output=True,
        text=True,
        timeout=300,
    ).stdout


def test_python_dash_m_and_bench_smoke():
    out = _bench_stdout(
        "--steps", "40", "--num-envs", "2", "--env-id", MAIN_ID,
        "--control-modes", "pd_joint_delta_pos",
    )  # fmt: skip
    rows = [line for line in out.splitlines() if line.startswith("pd_joint_delta_pos")]
    assert len(rows) == 2, out
    assert "make_vec(2)" in rows[1]
    for row in rows:
        # ... steps/s, x our single, x MS2 single, peak RSS MB, load
        steps_per_s, peak_rss = float(row.split()[-5]), float(row.split()[-2])
        assert steps_per_s > 0 and peak_rss > 10


def test_bench_visual_smoke():
    out = _bench_stdout(
        "--visual", "--steps", "10", "--num-envs", "2", "--obs-modes", "rgbd",
        "--env-id", "PickCube-v0",
    )  # fmt: skip
    rows = [line for line in out.splitlines() if line.startswith("rgbd")]
    assert len(rows) == 2 and "make_vec(2)" in rows[1], out
    for row in rows:
        # ... steps/s, cpu ms/step, x our single, x MS2 single, peak RSS MB, MB/extra env,
        # triangles/cam, load
        fields = row.split()
        assert float(fields[-8]) > 0 and float(fields[-4]) > 10 and int(fields[-2]) > 100
    # MB per extra env: only for the vector env (the single env is the baseline).
    assert rows[0].split()[-3] == "-" and float(rows[1].split()[-3]) > -1000, out


def test_bench_of_a_mobile_task_uses_its_base_control_mode():
    # The Panda modes (pd_ee_delta_pose, pd_joint_delta_pos) do not exist on the mobile robots:
    # without --control-modes the task's default mode is benchmarked, with no ManiSkill2 ratio.
    out = _bench_stdout("--steps", "10", "--num-envs", "", "--env-id", "OpenCabinetDrawer-v1")
    rows = [line for line in out.splitlines() if line.startswith("base_pd_joint_vel_arm")]
    assert len(rows) == 1 and "gym.make (1 env)" in rows[0], out
    # ... steps/s, x our single, x MS2 single, peak RSS MB, load
    fields = rows[0].split()
    assert float(fields[-5]) > 0 and fields[-3] == "-", out


def test_bench_rounds_end_with_medians_against_each_rounds_single_env():
    out = _bench_stdout(
        "--steps", "20", "--num-envs", "2", "--env-id", MAIN_ID, "--rounds", "2",
        "--control-modes", "pd_joint_delta_pos",
    )  # fmt: skip
    lines = out.splitlines()
    assert "round 1 of 2" in lines and "round 2 of 2" in lines, out
    at = next(i for i, line in enumerate(lines) if line.startswith("medians over 2 rounds"))
    measured = [line for line in lines[:at] if line.startswith("pd_joint_delta_pos")]
    medians = [line for line in lines[at + 1 :] if line.startswith("pd_joint_delta_pos")]
    assert len(measured) == 4 and len(medians) == 2, out
    # The single env's row is its own baseline; make_vec(2)'s ratio is the median of the two
    # rounds' ratios (each against its own round's single env), within their range.
    assert medians[0].split()[-2:] == ["1.00", "1.00-1.00"], out
    vec_ratios = sorted(float(line.split()[-4]) for line in measured if "make_vec(2)" in line)
    ratio, spread = float(medians[1].split()[-2]), medians[1].split()[-1]
    low, high = (float(x) for x in spread.split("-"))
    assert low <= ratio <= high and low > 0, out
    assert abs(low - vec_ratios[0]) < 0.006 and abs(high - vec_ratios[1]) < 0.006, out


def test_bench_rounds_must_be_positive_and_state_only(capsys):
    assert main(["bench", "--rounds", "0"]) == 2
    assert "--rounds must be at least 1, got 0" in capsys.readouterr().err
    assert main(["bench", "--visual", "--rounds", "3"]) == 2
    assert "--rounds is for the state rows" in capsys.readouterr().err
