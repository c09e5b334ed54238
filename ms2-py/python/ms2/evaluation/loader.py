"""Loading a solution file: import it by path and find its ``UserPolicy`` class."""

from __future__ import annotations

import importlib.util
import itertools
import os
import sys
import traceback
from pathlib import Path
from typing import Any

from .guard import describe_exception

#: The methods a ``UserPolicy`` must have (ManiSkill2's interface).
REQUIRED_METHODS = ("act", "reset", "get_obs_mode", "get_control_mode")

_module_numbers = itertools.count()


class SolutionError(ValueError):
    """A solution that cannot be evaluated at all: a missing file, an import error, no
    ``UserPolicy``, or modes the env refuses. The message names the file or the method."""


def load_solution(path: str | os.PathLike[str], class_name: str = "UserPolicy") -> type:
    """Imports the Python file ``path`` (as ManiSkill2's ``user_solution.py``) and returns its
    ``class_name`` class.

    The file's directory is put at the front of ``sys.path`` (and left there), so the
    solution can import modules next to it, also later from inside ``act``.

    Raises :class:`SolutionError` naming the file: it does not exist, its import raised (the
    exception and the line of the file), or it defines no such class or the class lacks one of
    :data:`REQUIRED_METHODS`.
    """
    path = Path(path)
    if not path.exists():
        raise SolutionError(f"solution file {path} does not exist")
    if not path.is_file():
        raise SolutionError(f"solution {path} is not a file (expected a Python file)")
    path = path.resolve()
    module_name = f"ms2_user_solution_{next(_module_numbers)}"
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise SolutionError(f"solution file {path} cannot be imported (expected a .py file)")
    folder = str(path.parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except (Exception, SystemExit) as err:
        sys.modules.pop(module_name, None)
        raise SolutionError(
            f"importing solution {path} failed{_line_in(err, path)}: {describe_exception(err)}"
        ) from err
    cls = getattr(module, class_name, None)
    if cls is None:
        raise SolutionError(
            f"solution {path} defines no {class_name} (expected a class {class_name}(BasePolicy) "
            "from ms2.evaluation.solution)"
        )
    if not isinstance(cls, type):
        raise SolutionError(
            f"{class_name} in solution {path} must be a class, got {type(cls).__name__}"
        )
    missing = [m for m in REQUIRED_METHODS if not callable(getattr(cls, m, None))]
    if missing:
        raise SolutionError(
            f"{class_name} in solution {path} lacks {missing} (subclass "
            "ms2.evaluation.solution.BasePolicy)"
        )
    return cls


def _line_in(err: BaseException, path: Path) -> str:
    """`` at line N`` for the deepest frame of ``err``'s traceback in ``path`` ('' if none)."""
    line: Any = None
    for frame in traceback.extract_tb(err.__traceback__):
        if Path(frame.filename) == path:
            line = frame.lineno
    if line is None and isinstance(err, SyntaxError) and err.filename == str(path):
        line = err.lineno
    return f" at line {line}" if line is not None else ""


__all__ = ["REQUIRED_METHODS", "SolutionError", "load_solution"]
