"""The command line as a user meets it: ``--version``, defaults in every option's help, one
meaning per short flag, each task's own default control mode, and a quiet stderr on render."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import ms2
import pytest
from ms2.cli import build_parser, main

#: What each short flag may stand for, in every subcommand.
SHORT_FLAG_MEANINGS = {
    "-h": {"help"},
    "-n": {"episodes", "num_episodes", "count"},  # how many episodes
    "-o": {"obs_mode"},
    "-c": {"control_mode", "target_control_mode"},
    "-w": {"workers", "num_workers"},
    "-v": {"verbose"},
    "-q": {"quiet"},
    "-e": {"env_id"},
}
#: Where a short flag means something else, by (subcommand, flag): ManiSkill2's evaluation
#: (``run_evaluation -e ID -o DIR``), which ``ms2 evaluate`` follows as issue #22 writes it.
SHORT_FLAG_EXCEPTIONS = {
    ("ms2 evaluate", "-o"): {"output_dir"},
    ("ms2 leaderboard", "-o"): {"output"},
}


def _parsers(parser: argparse.ArgumentParser, name: str = "ms2"):
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _parsers(sub, f"{name} {sub_name}")


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"ms2 {ms2.__version__}"


def test_every_option_has_help_showing_its_default():
    for name, parser in _parsers(build_parser()):
        formatter = parser._get_formatter()
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction) or action.help == argparse.SUPPRESS:
                continue
            if action.dest in ("help", "version"):
                continue
            assert action.help, f"{name} {action.option_strings or action.dest} has no help"
            required = action.required or (not action.option_strings and action.nargs is None)
            if required:  # nothing to default to
                continue
            shown = formatter._get_help_string(action) or ""
            assert "default" in shown.lower(), f"{name} {action.dest}: {shown!r}"


def test_short_flags_mean_one_thing_everywhere():
    seen: dict[str, set[str]] = {}
    for name, parser in _parsers(build_parser()):
        for action in parser._actions:
            for flag in action.option_strings:
                if flag.startswith("--"):
                    continue
                allowed = SHORT_FLAG_EXCEPTIONS.get((name, flag))
                if allowed is not None:
                    assert action.dest in allowed, f"{name} {flag} means {action.dest}"
                    continue
                seen.setdefault(flag, set()).add(action.dest)
    for flag, dests in seen.items():
        assert flag in SHORT_FLAG_MEANINGS, f"unexpected short flag {flag} ({dests})"
        assert dests <= SHORT_FLAG_MEANINGS[flag], f"{flag} means {dests}"


def test_run_uses_each_task_default_control_mode(capsys):
    assert main(["run", "Fill-v0", "--policy", "scripted", "-n", "1", "-q"]) == 0
    out = capsys.readouterr().out
    assert "Fill-v0 [pd_joint_delta_pos] scripted policy: success rate 1/1" in out


def test_rendering_prints_nothing_on_stderr_without_xdg_runtime_dir():
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_RUNTIME_DIR", "NODEVICE_SELECT")}
    env["WAYLAND_DISPLAY"] = "wayland-0"  # a session variable pointing at no compositor
    code = (
        "import gymnasium as gym, ms2\n"
        "env = gym.make('PickCube-v0', obs_mode='rgbd', render_mode='rgb_array')\n"
        "env.reset(seed=0); env.render()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert "XDG_RUNTIME_DIR" not in done.stderr
    assert done.stderr.strip() == ""


def test_readme_example_writes_a_video_and_a_trajectory(tmp_path, monkeypatch, capsys):
    readme = (Path(__file__).parents[2] / "README.md").read_text()
    example = readme.split("## Example", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    assert len(example.strip().splitlines()) <= 15
    monkeypatch.chdir(tmp_path)
    exec(compile(example, "README.md", "exec"), {})
    assert "success: True" in capsys.readouterr().out
    assert (tmp_path / "out" / "episode_0.mp4").stat().st_size > 0
    assert (tmp_path / "out" / "trajectory.h5").exists()
    assert (tmp_path / "out" / "trajectory.json").exists()
