"""Scale-out on Ray (:mod:`ms2.distributed`, docs/ray.md).

Without Ray: the ordered chunk stream (order, prefetch bound, resubmission of lost chunks,
errors), ``generate`` / ``run_evaluation`` through a stand-in for Ray's tasks (same files as a
local run, also when a chunk is lost and resubmitted), and the error when Ray is missing.

With ``MS2_TEST_RAY=1`` (scripts/test_ray.sh; needs ``ms2[ray]``): a cluster of separate
processes on 127.0.0.1 (head + two worker nodes, ``ray_cluster.py``): ``ms2 demos generate
--ray`` with a worker node killed mid-run writes the same files as a local run; ``ms2 evaluate
--ray`` gives a local run's results; the RL rollouts example samples on the cluster.
"""

from __future__ import annotations

import json
import os
import pickle
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from ms2 import demos
from ms2.cli import main
from ms2.distributed import ChunkLostError, OrderedChunks, RayOptions
from ms2.evaluation import evaluator

ENV_ID = "PickCube-v0"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SOLUTION = EXAMPLES / "evaluation" / "pickcube_solution.py"
RAY_TESTS = os.environ.get("MS2_TEST_RAY") == "1"
needs_cluster = pytest.mark.skipif(
    not RAY_TESTS, reason="a real Ray cluster: MS2_TEST_RAY=1 (scripts/test_ray.sh)"
)


class LostTask(Exception):
    """A stand-in for Ray's errors of a dead worker or node."""


class FakeTasks:
    """``submit`` / ``get`` over a local function, counting what is in flight and losing the
    first attempt of the chunks starting at the items in ``lose``."""

    def __init__(self, function, lose=(), key=lambda item: item):
        self.function = function
        self.lose = set(lose)
        self.key = key
        self.pending = 0
        self.max_pending = 0
        self.submitted = []

    def submit(self, chunk):
        self.pending += 1
        self.max_pending = max(self.max_pending, self.pending)
        self.submitted.append(list(chunk))
        return list(chunk)

    def get(self, chunk):
        self.pending -= 1
        if self.key(chunk[0]) in self.lose:
            self.lose.discard(self.key(chunk[0]))
            raise LostTask(f"node died running {chunk}")
        # Results cross a process boundary on Ray: pickled.
        return pickle.loads(pickle.dumps(self.function(chunk)))

    def stream(self, items, task_size, **kwargs):
        return OrderedChunks(
            items,
            task_size,
            self.submit,
            self.get,
            is_lost=lambda err: isinstance(err, LostTask),
            **kwargs,
        )


def test_chunks_come_back_in_item_order_with_a_bounded_prefetch():
    tasks = FakeTasks(lambda chunk: [x * x for x in chunk])
    stream = tasks.stream(range(3, 20), 4, in_flight=2)
    assert stream.take(1) == [9]
    assert tasks.max_pending <= 2
    assert stream.take(6) == [x * x for x in range(4, 10)]  # across a chunk boundary
    assert list(stream) == [x * x for x in range(10, 20)]
    assert tasks.max_pending <= 2
    assert [len(c) for c in tasks.submitted] == [4, 4, 4, 4, 1]
    with pytest.raises(IndexError, match="all 17 items"):
        stream.take(1)


def test_a_lost_chunk_is_resubmitted_and_its_results_keep_their_place():
    tasks = FakeTasks(lambda chunk: [str(x) for x in chunk], lose={4, 8})
    stream = tasks.stream(list(range(10)), 2, in_flight=3, max_resubmits=1)
    assert list(stream) == [str(x) for x in range(10)]
    assert stream.resubmitted == 2
    assert tasks.submitted.count([4, 5]) == 2 and tasks.submitted.count([0, 1]) == 1


def test_a_chunk_lost_more_often_than_allowed_names_its_items():
    tasks = FakeTasks(lambda chunk: list(chunk), lose={104})
    stream = tasks.stream(range(100, 110), 2, max_resubmits=0)
    assert stream.take(4) == [100, 101, 102, 103]
    with pytest.raises(ChunkLostError, match=r"items 4\.\.5 \(seeds 104\.\.105\)"):
        stream.take(1)


def test_errors_of_the_task_itself_are_not_retried():
    def fail(chunk):
        raise ZeroDivisionError("bad chunk")

    tasks = FakeTasks(fail)
    stream = tasks.stream(range(4), 2, max_resubmits=5)
    with pytest.raises(ZeroDivisionError, match="bad chunk"):
        stream.take(1)
    assert stream.resubmitted == 0


def test_a_task_returning_the_wrong_number_of_results_is_an_error():
    tasks = FakeTasks(lambda chunk: list(chunk)[:-1])
    with pytest.raises(RuntimeError, match="returned 1 results, expected 2"):
        tasks.stream(range(4), 2).take(1)


def test_close_cancels_the_chunks_still_running():
    tasks = FakeTasks(lambda chunk: list(chunk))
    cancelled = []
    stream = OrderedChunks(
        range(20), 2, tasks.submit, tasks.get, in_flight=3, cancel=cancelled.append
    )
    stream.take(1)
    stream.close()
    assert cancelled == [[2, 3], [4, 5], [6, 7]]


@pytest.fixture
def fake_ray(monkeypatch):
    """``ray_chunks`` replaced by local tasks (losing the first attempt of the chunks that
    start at the seeds / episode indices in ``fake_ray.lose``); returns the FakeTasks list."""
    made = []

    def fake_ray_chunks(items, function, args, options, default_task_size):
        def run(chunk):
            return function(chunk, *pickle.loads(pickle.dumps(args)))

        episode_id = lambda item: getattr(item, "episode_id", item)  # noqa: E731
        tasks = FakeTasks(run, fake_ray_chunks.lose, key=episode_id)
        made.append(tasks)
        size = options.task_size or default_task_size
        return tasks.stream(items, size, in_flight=3, max_resubmits=options.max_resubmits)

    fake_ray_chunks.lose = set()
    monkeypatch.setattr(demos, "ray_chunks", fake_ray_chunks)
    monkeypatch.setattr(evaluator, "ray_chunks", fake_ray_chunks)
    fake_ray_chunks.made = made
    return fake_ray_chunks


def assert_same_trajectory_files(a: Path, b: Path):
    """Byte-identical ``.h5`` and ``.json`` (ms2's writer embeds no timestamps)."""
    assert a.read_bytes() == b.read_bytes()
    assert a.with_suffix(".json").read_bytes() == b.with_suffix(".json").read_bytes()


def test_generate_over_chunk_tasks_writes_the_local_runs_files(tmp_path, fake_ray):
    local = demos.generate(
        ENV_ID, 7, tmp_path / "local.h5", policy="scripted", chunk_size=3, progress=False
    )
    fake_ray.lose = {2}  # the task of seeds 2..3 dies once
    remote = demos.generate(
        ENV_ID,
        7,
        tmp_path / "ray.h5",
        policy="scripted",
        chunk_size=3,
        progress=False,
        ray=RayOptions(task_size=2),
    )
    assert remote.resubmitted_chunks == 1
    assert (remote.num_episodes, remote.seeds_tried) == (local.num_episodes, local.seeds_tried)
    assert_same_trajectory_files(tmp_path / "local.h5", tmp_path / "ray.h5")
    # Seeds beyond those the local run tried were run ahead; their episodes were dropped.
    submitted = [s for chunk in fake_ray.made[0].submitted for s in chunk]
    assert max(submitted) >= local.seeds_tried


def without_timings(results: dict) -> dict:
    results = dict(results)
    results.pop("seconds")
    results["episodes"] = [{**e, "seconds": None} for e in results["episodes"]]
    return results


def test_evaluate_over_chunk_tasks_gives_the_local_results(tmp_path, fake_ray):
    local = evaluator.run_evaluation(ENV_ID, SOLUTION, tmp_path / "local", num_episodes=5)
    fake_ray.lose = {2}
    remote = evaluator.run_evaluation(
        ENV_ID, SOLUTION, tmp_path / "ray", num_episodes=5, ray=RayOptions(task_size=2)
    )
    assert without_timings(remote) == without_timings(local)
    assert [e["episode_id"] for e in remote["episodes"]] == list(range(5))
    for name in ("episode_results.json", "average_metrics.json"):
        assert (tmp_path / "local" / name).read_bytes() == (tmp_path / "ray" / name).read_bytes()


def test_evaluate_on_ray_refuses_a_policy_class_and_videos(tmp_path):
    from ms2.evaluation.loader import load_solution

    cls = load_solution(SOLUTION)
    with pytest.raises(ValueError, match="needs a solution file path"):
        evaluator.run_evaluation(ENV_ID, cls, tmp_path, num_episodes=1, ray=RayOptions())
    with pytest.raises(ValueError, match="records no videos"):
        evaluator.run_evaluation(
            ENV_ID, SOLUTION, tmp_path, num_episodes=1, record_dir="@", ray=RayOptions()
        )


def test_ray_options_name_bad_values():
    with pytest.raises(ValueError, match="task_size must be >= 1, got 0"):
        RayOptions(task_size=0)
    with pytest.raises(TypeError, match="max_retries must be an int, got str"):
        RayOptions(max_retries="3")
    with pytest.raises(ValueError, match="Ray address must be a non-empty string"):
        RayOptions(address="")


def test_ray_flag_without_ray_installed_says_how_to_install_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    out = tmp_path / "demos.h5"
    argv = ["demos", "generate", ENV_ID, "-n", "1", "--output", str(out), "-q", "--ray"]
    assert main(argv) == 2
    assert "pip install 'ms2[ray]'" in capsys.readouterr().err
    argv = ["evaluate", "-e", ENV_ID, "--solution", str(SOLUTION), "-o", str(tmp_path / "ev")]
    assert main([*argv, "-n", "1", "-q", "--ray", "127.0.0.1:1"]) == 2
    assert "pip install 'ms2[ray]'" in capsys.readouterr().err


def test_an_address_where_no_head_listens_is_named_at_once():
    from ms2.distributed import check_reachable

    with pytest.raises(RuntimeError, match=r"no Ray head answers at '127\.0\.0\.1:1'"):
        check_reachable("127.0.0.1:1")
    check_reachable("auto")  # left to Ray


# --- a real cluster (opt-in) -------------------------------------------------------------------


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """Head (no CPUs) + two one-CPU worker nodes, each its own ``ray start`` process tree."""
    pytest.importorskip("ray")
    sys.path.insert(0, str(Path(__file__).parent))
    from ray_cluster import LocalRayCluster

    with LocalRayCluster(tmp_path_factory.mktemp("ray")) as c:
        c.start_head()
        c.add_worker()
        c.add_worker()
        yield c


def run_ms2(cluster, *argv: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "ms2", *argv],
        env=cluster.env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def committed_episodes(h5: Path) -> int:
    try:
        return len(json.loads(h5.with_suffix(".json").read_text())["episodes"])
    except (OSError, ValueError, KeyError):
        return 0


@needs_cluster
def test_evaluate_on_a_cluster_gives_the_local_results(cluster, tmp_path):
    argv = ["evaluate", "-e", ENV_ID, "--solution", str(SOLUTION), "-n", "6", "-q"]
    local = run_ms2(cluster, *argv, "-o", str(tmp_path / "local"))
    remote = run_ms2(cluster, *argv, "-o", str(tmp_path / "ray"), "--ray", cluster.address)
    for proc in (local, remote):
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err
    read = [json.loads((tmp_path / d / "results.json").read_text()) for d in ("local", "ray")]
    assert without_timings(read[0]) == without_timings(read[1])


ROLLOUT_CHECK = """
import importlib.util, sys
import numpy as np
spec = importlib.util.spec_from_file_location("ray_rollouts", sys.argv[1])
example = importlib.util.module_from_spec(spec)
spec.loader.exec_module(example)
out = example.run(sys.argv[2], actors=2, num_envs=2, steps=30, iterations=2)
assert len(out["batches"]) == 2
for batch in out["batches"]:
    assert batch["obs"].shape[:2] == (30, 2) and batch["actions"].shape[:2] == (30, 2)
    assert batch["rewards"].shape == batch["dones"].shape == batch["valid"].shape == (30, 2)
    assert np.isfinite(batch["rewards"]).all()
# Differently seeded pools: the actors' first observations differ.
assert not np.array_equal(out["batches"][0]["obs"][0], out["batches"][1]["obs"][0])
assert np.abs(out["weights"]).sum() > 0  # the learner moved the policy
print("rollouts checked")
"""


@needs_cluster
def test_rollout_actors_sample_make_vec_pools_on_the_cluster(cluster):
    """examples/ray_rollouts.py: two actors' make_vec pools sample batches for the learner
    (run in a fresh process: Ray keeps one cluster connection and token per process)."""
    proc = subprocess.run(
        [sys.executable, "-c", ROLLOUT_CHECK, str(EXAMPLES / "ray_rollouts.py"), cluster.address],
        env=cluster.env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0 and "rollouts checked" in proc.stdout, proc.stderr[-3000:]


@needs_cluster
@pytest.mark.parametrize("ray_retries", [3, 0], ids=["ray-retries", "driver-resubmits"])
def test_a_worker_node_killed_mid_run_loses_no_episode(cluster, tmp_path, ray_retries):
    """``ms2 demos generate --ray``: one of two worker nodes is killed (SIGKILL to its raylet
    and worker processes) once the first chunks are committed; its tasks are run again on the
    other node — by Ray (``--ray-max-retries 3``) or, with Ray's retries off, by ms2's driver
    resubmitting the lost chunk — and the files equal a local run's byte for byte."""
    n, chunk = "60", "2"
    out = tmp_path / "ray.h5"
    proc = run_ms2(
        cluster, "demos", "generate", ENV_ID, "-n", n, "--output", str(out),
        "--chunk-size", chunk, "-q", "--ray", cluster.address,
        "--ray-max-retries", str(ray_retries),
    )  # fmt: skip
    deadline = time.monotonic() + 240
    while committed_episodes(out) < 4:
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline, "no chunk committed within 240 s"
        time.sleep(0.05)
    victim = next(i for i in range(1, len(cluster.nodes)) if i not in cluster.killed)
    cluster.kill_node(victim)
    killed_at = committed_episodes(out)
    assert proc.poll() is None and killed_at < int(n), "the run ended before the kill"
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr
    logs = stdout + stderr
    resubmitted = int(re.search(r"(\d+) lost chunk\(s\) resubmitted", stdout).group(1))
    if ray_retries:  # Ray re-ran the killed node's task (and says so in the driver's log)
        assert "node it was running on is dead" in logs or resubmitted > 0, logs
    else:
        assert resubmitted > 0, logs
    local = tmp_path / "local.h5"
    demos.generate(ENV_ID, int(n), local, chunk_size=int(chunk), progress=False)
    assert committed_episodes(out) == int(n)
    assert_same_trajectory_files(local, out)
    cluster.add_worker()  # back to two workers for the next test
