"""An evaluation's results: per-episode metrics, their averages, and the files they go to.

The output directory gets ManiSkill2's two files and ms2's summary, each written to a temporary
name and renamed (a reader never sees half a file):

* ``episode_results.json`` — ManiSkill2's: ``{episode_id: {metric: float}}``, every scalar of
  the episode's last ``info`` (``elapsed_steps``, ``success``, the task's terms), plus
  ``failed`` (1.0 when the solution failed the episode, whose ``success`` is then 0.0).
  Every episode has the same keys.
* ``average_metrics.json`` — ManiSkill2's: ``{metric: mean over the episodes}``.
* ``results.json`` — ms2's summary: the task, solution, modes, split, counts, success rate,
  mean episode length, the averages, and one entry per episode (seed, asset model where the
  task draws one, success, steps, seconds, failure kind and reason, video). ``ms2 leaderboard``
  reads it.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

#: Version of ``results.json``'s layout.
RESULTS_FORMAT = 1

#: The file names in an evaluation's output directory.
EPISODE_RESULTS_FILE = "episode_results.json"
AVERAGE_METRICS_FILE = "average_metrics.json"
RESULTS_FILE = "results.json"
ERROR_LOG_FILE = "error.log"


@dataclass
class EpisodeResult:
    """One evaluated episode."""

    episode_id: int | str
    seed: int | None
    metrics: dict[str, float]
    seconds: float
    failure_kind: str | None = None
    failure_reason: str | None = None
    failure_step: int | None = None
    video: str | None = None
    model_id: str | None = None

    @property
    def failed(self) -> bool:
        """Whether the solution failed the episode (an exception, bad action, timeout, ...)."""
        return self.failure_kind is not None

    @property
    def success(self) -> bool:
        """Whether the episode ended in success (never for a failed episode)."""
        return not self.failed and self.metrics.get("success", 0.0) > 0.5

    def to_json(self) -> dict[str, Any]:
        """This episode's entry in ``results.json``."""
        failure = None
        if self.failed:
            failure = {
                "kind": self.failure_kind,
                "reason": self.failure_reason,
                "step": self.failure_step,
            }
        return {
            "episode_id": self.episode_id,
            "seed": self.seed,
            "model_id": self.model_id,
            "success": self.success,
            "elapsed_steps": int(self.metrics.get("elapsed_steps", 0)),
            "seconds": round(self.seconds, 4),
            "failure": failure,
            "video": self.video,
        }


def extract_scalars(info: Mapping[str, Any], blacklist: Sequence[str] = ()) -> dict[str, float]:
    """The scalar entries of ``info`` as floats, nested dicts flattened with ``.``-joined keys
    (ManiSkill2's ``extract_scalars_from_info``): strings, ``None`` and arrays of more than one
    element are left out, as are keys in ``blacklist``."""
    out: dict[str, float] = {}
    for key, value in info.items():
        if key in blacklist or value is None:
            continue
        if isinstance(value, Mapping):
            for sub_key, sub_value in extract_scalars(value, blacklist).items():
                full = f"{key}.{sub_key}"
                if full not in blacklist:
                    out[full] = sub_value
        elif not isinstance(value, (str, bytes)) and np.size(value) == 1:
            try:
                out[key] = float(np.asarray(value).reshape(-1)[0])
            except (TypeError, ValueError):
                continue
    return out


def uniform_metrics(results: Sequence[EpisodeResult]) -> None:
    """Gives every episode the same metric keys (ManiSkill2's tooling merges them): a key an
    episode lacks (one whose env reset failed has no info) is set to 0.0 there."""
    keys: dict[str, None] = {}
    for result in results:
        keys.update(dict.fromkeys(result.metrics))
    for result in results:
        for key in keys:
            result.metrics.setdefault(key, 0.0)


def average_metrics(results: Sequence[EpisodeResult]) -> dict[str, float]:
    """The mean of each metric over ``results`` (ManiSkill2's ``average_metrics.json``)."""
    if not results:
        return {}
    keys = list(results[0].metrics)
    return {k: float(np.mean([r.metrics.get(k, 0.0) for r in results])) for k in keys}


def summarize(results: Sequence[EpisodeResult], header: Mapping[str, Any]) -> dict[str, Any]:
    """``results.json``'s content: ``header`` (env id, solution, modes, ...) then the counts,
    rates, averages and episode entries of ``results``."""
    n = len(results)
    successes = sum(r.success for r in results)
    failures: dict[str, int] = {}
    for r in results:
        if r.failure_kind is not None:
            failures[r.failure_kind] = failures.get(r.failure_kind, 0) + 1
    lengths = [r.metrics.get("elapsed_steps", 0.0) for r in results]
    return {
        "format": RESULTS_FORMAT,
        **header,
        "num_episodes": n,
        "num_successes": successes,
        "success_rate": successes / n if n else 0.0,
        "mean_episode_length": float(np.mean(lengths)) if n else 0.0,
        "num_failed": sum(failures.values()),
        "failures_by_kind": failures,
        "average_metrics": average_metrics(results),
        "episodes": [r.to_json() for r in results],
    }


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Writes ``text`` to ``path`` through a temporary file in the same directory and a rename,
    so ``path`` is either its old content or the whole new one. Returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def write_json_atomic(path: str | os.PathLike[str], data: Any) -> Path:
    """Writes ``data`` as indented JSON to ``path`` (atomically, see
    :func:`write_text_atomic`); non-finite floats are refused (``ValueError``)."""
    text = json.dumps(_finite(data), indent=2, allow_nan=False) + "\n"
    return write_text_atomic(path, text)


def _finite(data: Any) -> Any:
    """``data`` with non-finite floats replaced by ``None`` (JSON has no NaN)."""
    if isinstance(data, float) and not math.isfinite(data):
        return None
    if isinstance(data, Mapping):
        return {str(k): _finite(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_finite(v) for v in data]
    return data


def write_results(
    output_dir: str | os.PathLike[str],
    results: Sequence[EpisodeResult],
    header: Mapping[str, Any],
) -> dict[str, Path]:
    """Writes ``episode_results.json``, ``average_metrics.json`` and ``results.json`` into
    ``output_dir``; returns their paths by file name."""
    out = Path(output_dir)
    uniform_metrics(results)
    per_episode = {str(r.episode_id): r.metrics for r in results}
    return {
        EPISODE_RESULTS_FILE: write_json_atomic(out / EPISODE_RESULTS_FILE, per_episode),
        AVERAGE_METRICS_FILE: write_json_atomic(
            out / AVERAGE_METRICS_FILE, average_metrics(results)
        ),
        RESULTS_FILE: write_json_atomic(out / RESULTS_FILE, summarize(results, header)),
    }


def read_results(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Reads an evaluation's ``results.json`` (``path`` is the file or its directory);
    ``ValueError`` naming the file if it is missing, not JSON or not ms2's layout."""
    path = Path(path)
    if path.is_dir() or path.suffix != ".json":
        path = path / RESULTS_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as err:
        raise ValueError(
            f"no evaluation results at {path} (run `ms2 evaluate -o DIR` first)"
        ) from err
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ValueError(f"cannot read evaluation results {path}: {err}") from err
    required = ("env_id", "solution", "num_episodes", "success_rate", "mean_episode_length")
    if not isinstance(data, dict) or any(k not in data for k in required):
        raise ValueError(f"{path} is not an ms2 results.json (expected the keys {list(required)})")
    return data


__all__ = [
    "AVERAGE_METRICS_FILE",
    "EPISODE_RESULTS_FILE",
    "ERROR_LOG_FILE",
    "RESULTS_FILE",
    "EpisodeResult",
    "average_metrics",
    "extract_scalars",
    "read_results",
    "summarize",
    "write_json_atomic",
    "write_results",
    "write_text_atomic",
]
