"""Demo generation locally and on a 127.0.0.1 Ray cluster of 1, then 2 one-CPU worker nodes.

    python scripts/bench_ray_scaling.py [-n 200] [--chunk-size 8] [--repeats 2]

Runs ``ms2 demos generate PickCube-v0 -n N --chunk-size C`` with 1 local worker thread, then
with ``--ray`` on a cluster of separate ``ray start`` processes (head without CPUs, the
cluster of ms2-py/tests/ray_cluster.py) with one and then two worker nodes; prints episodes per
second (best of ``--repeats``; the CLI's own wall time, Ray start-up excluded) with the load
average before each run, and checks every run wrote the same files. Needs ``ms2[ray]``. The
numbers of docs/ray.md come from here.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ms2-py" / "tests"))

from ray_cluster import LocalRayCluster


def run(env: dict, out: Path, n: int, chunk: int, extra: list[str]) -> float:
    """Seconds ``ms2 demos generate`` reports for the run."""
    argv = [sys.executable, "-m", "ms2", "demos", "generate", "PickCube-v0", "-n", str(n)]
    argv += ["--output", str(out), "--chunk-size", str(chunk), "-q", *extra]
    proc = subprocess.run(argv, env=env, capture_output=True, text=True, check=True)
    return float(re.search(r" in ([\d.]+) s =", proc.stdout).group(1))


def measure(label: str, env: dict, tmp: Path, args: argparse.Namespace, extra: list[str]):
    best = None
    for i in range(args.repeats):
        load = os.getloadavg()[0]
        out = tmp / f"{label.replace(' ', '_')}_{i}.h5"
        seconds = run(env, out, args.n, args.chunk_size, extra)
        best = seconds if best is None else min(best, seconds)
        print(f"  {label}: {seconds:.1f} s ({args.n / seconds:.1f} ep/s), load before {load:.2f}")
    print(f"{label}: best {args.n / best:.1f} episodes/s")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=200, help="demos per run")
    parser.add_argument("--chunk-size", type=int, default=8, help="seeds per chunk / Ray task")
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores; load average {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        env = {**os.environ, "RAYON_NUM_THREADS": "1"}
        outputs = [measure("local, 1 thread", env, tmp, args, ["-w", "1"])]
        with LocalRayCluster(tmp / "ray") as cluster:
            cluster.start_head()
            for workers in (1, 2):
                cluster.add_worker()
                label = f"Ray, {workers} worker node(s)"
                outputs.append(
                    measure(label, cluster.env, tmp, args, ["--ray", cluster.address])
                )
        data = {p.read_bytes() + p.with_suffix(".json").read_bytes() for p in outputs}
        print(f"files identical across runs: {len(data) == 1}")


if __name__ == "__main__":
    main()
