"""Which episodes an evaluation runs: ManiSkill2's episode configuration files and the test split.

A configuration is ManiSkill2's JSON layout::

    {
      "env_info": {"env_id": "PickCube-v0", "env_kwargs": {"max_episode_steps": 100}},
      "episodes": [
        {"episode_id": 0, "reset_kwargs": {"seed": 0}},
        {"episode_id": 1, "reset_kwargs": {"seed": 17, "options": {"reconfigure": true}}}
      ]
    }

``env_kwargs`` (optional) are passed to ``gymnasium.make`` (the solution chooses ``obs_mode``
and ``control_mode``, so those two are refused there); each episode's ``reset_kwargs``
(optional: ``seed``, ``options``) to ``env.reset``; ``episode_id`` (optional, default the
episode's index) names the episode in the results and must be unique. Without a file,
:func:`seeded_config` makes episodes with seeds ``first_seed, first_seed + 1, ...``.

Tasks whose objects come in train and test model sets (:data:`MODEL_SPLIT_VARIABLES`) are
evaluated on the held-out ``test`` models by default: :func:`model_split` sets the task's
``MS2_*_MODELS`` variable while the env is made.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: The environment variable choosing each task's model set (``train``, ``test`` or ``partnet``),
#: read when the env is made. Tasks not listed have no held-out models in ms2 (PickSingleYCB /
#: EGAD draw from their train info json): their test episodes are seeded episodes.
MODEL_SPLIT_VARIABLES = {
    "TurnFaucet-v0": "MS2_FAUCET_MODELS",
    "OpenCabinetDrawer-v1": "MS2_CABINET_MODELS",
    "OpenCabinetDoor-v1": "MS2_CABINET_MODELS",
    "PushChair-v1": "MS2_CHAIR_MODELS",
    "MoveBucket-v1": "MS2_BUCKET_MODELS",
}

#: The model sets ``model_split`` accepts.
MODEL_SPLITS = ("test", "train", "partnet")

#: ``env_kwargs`` a configuration may not set: the solution chooses them.
_POLICY_KWARGS = ("obs_mode", "control_mode")

#: The keys of an episode's ``reset_kwargs`` (``env.reset``'s keywords).
_RESET_KEYS = ("seed", "options")


class ConfigError(ValueError):
    """A malformed episode configuration (the message names the file and the bad entry)."""


@dataclass
class EpisodeConfig:
    """One episode to evaluate: its id in the results and the keywords of ``env.reset``."""

    episode_id: int | str
    reset_kwargs: dict[str, Any] = field(default_factory=dict)


@dataclass
class EvaluationConfig:
    """The task, its ``gymnasium.make`` keywords and the episodes of an evaluation."""

    env_id: str
    env_kwargs: dict[str, Any]
    episodes: list[EpisodeConfig]

    def to_json(self) -> dict[str, Any]:
        """The configuration in ManiSkill2's JSON layout."""
        return {
            "env_info": {"env_id": self.env_id, "env_kwargs": dict(self.env_kwargs)},
            "episodes": [
                {"episode_id": e.episode_id, "reset_kwargs": dict(e.reset_kwargs)}
                for e in self.episodes
            ],
        }


def seeded_config(env_id: str, num_episodes: int, first_seed: int = 0) -> EvaluationConfig:
    """``num_episodes`` episodes of ``env_id`` with ids ``0, 1, ...`` and seeds
    ``first_seed + id``."""
    if isinstance(num_episodes, bool) or not isinstance(num_episodes, int) or num_episodes < 1:
        raise ValueError(f"num_episodes must be a positive int, got {num_episodes!r}")
    if isinstance(first_seed, bool) or not isinstance(first_seed, int) or first_seed < 0:
        raise ValueError(f"the first seed must be an int >= 0, got {first_seed!r}")
    episodes = [EpisodeConfig(i, {"seed": first_seed + i}) for i in range(num_episodes)]
    return EvaluationConfig(env_id, {}, episodes)


def load_config(path: str | os.PathLike[str], env_id: str) -> EvaluationConfig:
    """Reads and checks the configuration file ``path`` for ``env_id`` (:class:`ConfigError`
    naming the file and the problem: unreadable, not JSON, wrong layout, other task)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise ConfigError(f"cannot read episode config {path}: {err.strerror or err}") from err
    except UnicodeDecodeError as err:
        raise ConfigError(f"episode config {path} is not UTF-8 text: {err}") from err
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise ConfigError(f"episode config {path} is not valid JSON: {err}") from err
    return parse_config(data, env_id, source=str(path))


def parse_config(data: Any, env_id: str, source: str = "episode config") -> EvaluationConfig:
    """Checks ManiSkill2's configuration layout in ``data`` (parsed JSON) for ``env_id``."""

    def fail(what: str) -> ConfigError:
        return ConfigError(f"{source}: {what}")

    if not isinstance(data, Mapping):
        raise fail(f"expected a JSON object with env_info and episodes, got {_kind(data)}")
    env_info = data.get("env_info")
    if not isinstance(env_info, Mapping):
        raise fail(f'"env_info" must be an object with "env_id", got {_kind(env_info)}')
    config_env_id = env_info.get("env_id")
    if config_env_id != env_id:
        raise fail(f"env_info.env_id is {config_env_id!r}, but the evaluated task is {env_id!r}")
    env_kwargs = env_info.get("env_kwargs") or {}
    if not isinstance(env_kwargs, Mapping):
        raise fail(f"env_info.env_kwargs must be an object, got {_kind(env_kwargs)}")
    for key in _POLICY_KWARGS:
        if key in env_kwargs:
            raise fail(
                f"env_info.env_kwargs may not set {key!r}: the solution chooses it "
                f"(UserPolicy.get_{key}(env_id))"
            )
    raw_episodes = data.get("episodes")
    if not isinstance(raw_episodes, list) or not raw_episodes:
        raise fail(f'"episodes" must be a non-empty list, got {_kind(raw_episodes)}')
    episodes: list[EpisodeConfig] = []
    seen: set[int | str] = set()
    for index, raw in enumerate(raw_episodes):
        episodes.append(_parse_episode(raw, index, fail))
        episode_id = episodes[-1].episode_id
        if episode_id in seen:
            raise fail(f"episodes[{index}]: episode_id {episode_id!r} is not unique")
        seen.add(episode_id)
    return EvaluationConfig(env_id, dict(env_kwargs), episodes)


def _parse_episode(raw: Any, index: int, fail: Any) -> EpisodeConfig:
    where = f"episodes[{index}]"
    if not isinstance(raw, Mapping):
        raise fail(f"{where} must be an object, got {_kind(raw)}")
    episode_id = raw.get("episode_id", index)
    if isinstance(episode_id, bool) or not isinstance(episode_id, (int, str)):
        raise fail(f"{where}.episode_id must be an int or a string, got {episode_id!r}")
    reset_kwargs = raw.get("reset_kwargs") or {}
    if not isinstance(reset_kwargs, Mapping):
        raise fail(f"{where}.reset_kwargs must be an object, got {_kind(reset_kwargs)}")
    unknown = [k for k in reset_kwargs if k not in _RESET_KEYS]
    if unknown:
        raise fail(f"{where}.reset_kwargs has unknown key(s) {unknown}; valid: {list(_RESET_KEYS)}")
    seed = reset_kwargs.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise fail(f"{where}.reset_kwargs.seed must be an int >= 0 or null, got {seed!r}")
    options = reset_kwargs.get("options")
    if options is not None and not isinstance(options, Mapping):
        raise fail(f"{where}.reset_kwargs.options must be an object, got {_kind(options)}")
    return EpisodeConfig(episode_id, dict(reset_kwargs))


def _kind(value: Any) -> str:
    return "nothing" if value is None else f"{type(value).__name__} {value!r:.60}"


@contextmanager
def model_split(env_id: str, split: str) -> Iterator[str | None]:
    """While the block runs, ``env_id``'s model-set variable is ``split`` (one of
    :data:`MODEL_SPLITS`); yields the split used, ``None`` for a task without model sets
    (nothing changes then). The variable's previous value is restored afterwards."""
    if split not in MODEL_SPLITS:
        raise ValueError(f"model split must be one of {list(MODEL_SPLITS)}, got {split!r}")
    variable = MODEL_SPLIT_VARIABLES.get(env_id)
    if variable is None:
        yield None
        return
    previous = os.environ.get(variable)
    os.environ[variable] = split
    try:
        yield split
    finally:
        if previous is None:
            os.environ.pop(variable, None)
        else:
            os.environ[variable] = previous


__all__ = [
    "MODEL_SPLITS",
    "MODEL_SPLIT_VARIABLES",
    "ConfigError",
    "EpisodeConfig",
    "EvaluationConfig",
    "load_config",
    "model_split",
    "parse_config",
    "seeded_config",
]
