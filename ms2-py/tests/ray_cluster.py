"""A Ray cluster of separate processes on 127.0.0.1 for the opt-in Ray tests (``MS2_TEST_RAY=1``).

Each node is one ``ray start --block`` process tree in its own session (a head with no CPUs, and
worker nodes with one CPU each), so a test can kill one node abruptly (SIGKILL to its process
group: raylet and worker processes die at once) and stop everything it started, by process
group, without ``ray stop`` (which would stop every Ray process of the machine). The nodes
authenticate with a fresh token (``RAY_AUTH_TOKEN``), not the user's ``~/.ray``.
"""

from __future__ import annotations

import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

#: Seconds a node may take to join.
JOIN_TIMEOUT = 90.0
#: Object store of each node (small: the machine is shared).
OBJECT_STORE_BYTES = 100 * 1024 * 1024


def free_port() -> int:
    """A TCP port nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalRayCluster:
    """Head + worker nodes as separate ``ray start`` processes, logs and sockets in ``root``."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        ray_bin = shutil.which("ray")
        if ray_bin is None:
            raise RuntimeError("the `ray` command is not on PATH (pip install 'ms2[ray]')")
        self.ray_bin = ray_bin
        self.env = {
            **os.environ,
            "RAY_AUTH_MODE": "token",
            "RAY_AUTH_TOKEN": secrets.token_hex(32),
            "RAYON_NUM_THREADS": "1",
            "RAY_ADDRESS": "",
        }
        self.nodes: list[subprocess.Popen] = []  # [head, worker 1, ...]
        self.logs: list[Path] = []
        self.killed: set[int] = set()  # nodes killed on purpose

    def _start(self, name: str, args: list[str]) -> subprocess.Popen:
        # Every node binds its own ports: nodes on one host otherwise race for the same ones.
        ports = [
            "--node-manager-port",
            "--object-manager-port",
            "--metrics-export-port",
            "--dashboard-agent-listen-port",
            "--dashboard-agent-grpc-port",
            "--runtime-env-agent-port",
        ]
        argv = [self.ray_bin, "start", "--block", "--node-ip-address", "127.0.0.1"]
        argv += ["--temp-dir", str(self.root / "tmp"), "--disable-usage-stats"]
        argv += ["--object-store-memory", str(OBJECT_STORE_BYTES)]
        for flag in ports:
            argv += [flag, str(free_port())]
        log = self.root / f"{name}.log"
        self.logs.append(log)
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                argv + args,
                stdout=out,
                stderr=subprocess.STDOUT,
                env=self.env,
                start_new_session=True,
            )
        self.nodes.append(proc)
        return proc

    def start_head(self) -> None:
        """Starts the head node (GCS, no CPUs: tasks run on worker nodes only)."""
        head = ["--head", "--port", str(self.port), "--num-cpus", "0"]
        self._start("head", [*head, "--include-dashboard=false"])
        self.wait_for_cpus(0)

    def add_worker(self, num_cpus: int = 1) -> int:
        """Starts a worker node of ``num_cpus`` CPUs and waits until it joined; its index."""
        before = self.cpus()
        args = ["--address", self.address, "--num-cpus", str(num_cpus)]
        self._start(f"worker{len(self.nodes)}", args)
        self.wait_for_cpus(before + num_cpus)
        return len(self.nodes) - 1

    def cpus(self) -> int:
        """CPUs of the live nodes (``ray status``); -1 while the head does not answer."""
        out = subprocess.run(
            [self.ray_bin, "status", "--address", self.address],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        if out.returncode != 0 or "Resources" not in out.stdout:
            return -1
        match = re.search(r"/(\d+(?:\.\d+)?) CPU", out.stdout)
        return 0 if match is None else int(float(match.group(1)))

    def wait_for_cpus(self, cpus: int) -> None:
        """Waits until the cluster has ``cpus`` CPUs (``RuntimeError`` with the logs' tails if
        a node exited or ``JOIN_TIMEOUT`` passed)."""
        deadline = time.monotonic() + JOIN_TIMEOUT
        while time.monotonic() < deadline:
            dead = [
                i for i, p in enumerate(self.nodes) if i not in self.killed and p.poll() is not None
            ]
            if dead:
                raise RuntimeError(f"Ray node {dead[0]} exited:\n{self._tail(dead[0])}")
            if self.cpus() == cpus:
                return
            time.sleep(1.0)
        raise RuntimeError(f"the Ray cluster did not reach {cpus} CPUs:\n{self._tail(-1)}")

    def _tail(self, index: int) -> str:
        return self.logs[index].read_text(errors="replace")[-3000:]

    def kill_node(self, index: int) -> None:
        """Kills node ``index`` abruptly: SIGKILL to its whole process group."""
        self.killed.add(index)
        try:
            os.killpg(self.nodes[index].pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.nodes[index].wait(timeout=30)

    def stop(self) -> None:
        """Kills every node this cluster started (workers first, then the head)."""
        for index in reversed(range(len(self.nodes))):
            self.kill_node(index)

    def __enter__(self) -> LocalRayCluster:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
