"""Scale-out on Ray: chunks of seeds (or episodes) run as Ray tasks, merged back in order.

``ms2 demos generate ... --ray [ADDRESS]`` and ``ms2 evaluate ... --ray [ADDRESS]`` hand their
work to a Ray cluster instead of local native threads. The driver (the ``ms2`` process) cuts
its items (seeds, episode configurations) into chunks of ``task_size``; each chunk is one Ray
task running the same per-chunk function a local run calls (a pure function of its items), and
the driver takes the results back **in item order** and writes the output files itself with
the local run's writer. A Ray run therefore writes the same files as a local run.

Lost work is retried: Ray re-runs a task whose worker process or node died (``max_retries``),
and should a task still end in a system error (its node gone after Ray's retries, its result
lost), the driver submits it again, up to ``max_resubmits`` times per chunk. An exception the
chunk function itself raises is not retried (it would raise again): it ends the run.

:class:`OrderedChunks` is the part that needs no Ray (ordering, prefetching, resubmission over
``submit``/``get`` callables); :func:`ray_chunks` plugs Ray's tasks into it. Ray is an optional
dependency (``pip install 'ms2[ray]'``), imported only when a run asks for it.
"""

from __future__ import annotations

import os
import socket
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

#: What to install for ``--ray``.
RAY_EXTRA_HINT = "pip install 'ms2[ray]' (or pip install ray)"


@dataclass
class RayOptions:
    """How a run uses Ray.

    Args:
        address: the cluster to join (``ray.init(address=...)``, e.g. ``"127.0.0.1:6379"`` or
            ``"auto"``); ``None`` starts (or joins) a local Ray on this machine.
        task_size: items (seeds or episodes) per Ray task; ``None``: the caller's chunk size.
        num_cpus: CPUs each task reserves (also its native worker threads in ``demos``).
        max_retries: Ray's re-runs of a task whose worker process or node died.
        max_resubmits: further submissions of a chunk whose task still ended in a system error.
        in_flight: tasks submitted ahead of the one the driver waits for (``None``: twice the
            cluster's CPUs divided by ``num_cpus``, at least 2).
    """

    address: str | None = None
    task_size: int | None = None
    num_cpus: int = 1
    max_retries: int = 3
    max_resubmits: int = 2
    in_flight: int | None = None

    def __post_init__(self) -> None:
        for name, low in (("num_cpus", 1), ("max_retries", 0), ("max_resubmits", 0)):
            _check_count(name, getattr(self, name), low)
        for name in ("task_size", "in_flight"):
            if getattr(self, name) is not None:
                _check_count(name, getattr(self, name), 1)
        if self.address is not None and (not isinstance(self.address, str) or not self.address):
            raise ValueError(
                f"Ray address must be a non-empty string such as '127.0.0.1:6379' or 'auto', "
                f"got {self.address!r}"
            )


def _check_count(name: str, value: Any, low: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"RayOptions.{name} must be an int, got {type(value).__name__} {value!r}")
    if value < low:
        raise ValueError(f"RayOptions.{name} must be >= {low}, got {value}")


class ChunkLostError(RuntimeError):
    """A chunk whose task kept failing for system reasons (worker or node deaths) after every
    retry and resubmission; the message names its items."""


class OrderedChunks:
    """Runs ``items`` in chunks of ``task_size`` through ``submit`` / ``get`` and hands the
    per-item results back in item order.

    ``submit(chunk)`` starts the work on a chunk (a slice of ``items``) and returns a handle;
    ``get(handle)`` waits for it and returns one result per item, in the chunk's order. Up to
    ``in_flight`` chunks run ahead of the one being waited for. When ``get`` raises an
    exception for which ``is_lost(err)`` is true, the chunk is submitted again (at most
    ``max_resubmits`` times, then :class:`ChunkLostError`); other exceptions propagate.

    :meth:`take` returns the next ``n`` results; iterating yields them one by one;
    :meth:`close` cancels what is still running (``cancel(handle)``).
    """

    def __init__(
        self,
        items: Sequence[Any],
        task_size: int,
        submit: Callable[[Sequence[Any]], Any],
        get: Callable[[Any], Sequence[Any]],
        *,
        in_flight: int = 2,
        max_resubmits: int = 0,
        is_lost: Callable[[BaseException], bool] = lambda err: False,
        cancel: Callable[[Any], None] | None = None,
    ) -> None:
        _check_count("task_size", task_size, 1)
        _check_count("in_flight", in_flight, 1)
        _check_count("max_resubmits", max_resubmits, 0)
        self.items = items
        self.task_size = task_size
        self._submit, self._get, self._cancel = submit, get, cancel
        self._is_lost = is_lost
        self.in_flight = in_flight
        self.max_resubmits = max_resubmits
        self._next_start = 0  # first item not yet submitted
        self._pending: deque[tuple[int, Any]] = deque()  # (start, handle), in item order
        self._ready: deque[Any] = deque()  # results of the chunk being consumed
        self.resubmitted = 0  # chunks submitted again after a lost task
        self.consumed = 0  # results handed out so far

    def _fill(self) -> None:
        while len(self._pending) < self.in_flight and self._next_start < len(self.items):
            start = self._next_start
            chunk = self.items[start : start + self.task_size]
            self._pending.append((start, self._submit(chunk)))
            self._next_start += len(chunk)

    def _next_chunk(self) -> None:
        self._fill()
        if not self._pending:
            raise IndexError(f"all {len(self.items)} items were taken")
        start, handle = self._pending.popleft()
        chunk = self.items[start : start + self.task_size]
        attempts = 0
        while True:
            try:
                results = list(self._get(handle))
                break
            except Exception as err:
                if not self._is_lost(err):
                    raise
                if attempts >= self.max_resubmits:
                    raise ChunkLostError(
                        f"the task of items {start}..{start + len(chunk) - 1} "
                        f"({_describe(chunk)}) was lost {attempts + 1} time(s), last: {err}"
                    ) from err
                attempts += 1
                self.resubmitted += 1
                handle = self._submit(chunk)
        if len(results) != len(chunk):
            raise RuntimeError(
                f"the task of items {start}..{start + len(chunk) - 1} returned {len(results)} "
                f"results, expected {len(chunk)}"
            )
        self._ready.extend(results)
        self._fill()  # keep the cluster busy while the driver consumes

    def take(self, n: int) -> list[Any]:
        """The next ``n`` results in item order (``IndexError`` past the last item)."""
        out = []
        while len(out) < n:
            if not self._ready:
                self._next_chunk()
            out.append(self._ready.popleft())
        self.consumed += len(out)
        return out

    def __iter__(self) -> Iterator[Any]:
        while self.consumed < len(self.items):
            yield self.take(1)[0]

    def close(self) -> None:
        """Cancels the chunks still submitted (when ``cancel`` was given) and forgets them."""
        while self._pending:
            _, handle = self._pending.popleft()
            if self._cancel is not None:
                try:
                    self._cancel(handle)
                except Exception:  # noqa: BLE001 - a task that already ended
                    pass
        self._ready.clear()

    def __enter__(self) -> OrderedChunks:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: ``--ray``'s value when given without an address: a local Ray.
LOCAL_RAY = "local"


def add_ray_arguments(parser: Any, items: str, default_task_size: str) -> None:
    """Adds ``--ray [ADDRESS]``, ``--ray-task-size`` and ``--ray-max-retries`` to a command
    whose work is ``items`` (e.g. ``"seeds"``), cut by default into ``default_task_size``."""
    parser.add_argument(
        "--ray",
        nargs="?",
        const=LOCAL_RAY,
        default=None,
        metavar="ADDRESS",
        help=f"spread the {items} over a Ray cluster (ADDRESS such as 127.0.0.1:6379 or 'auto'; "
        f"no ADDRESS: a local Ray); same output as a local run; needs {RAY_EXTRA_HINT}",
    )
    parser.add_argument(
        "--ray-task-size",
        type=int,
        default=None,
        metavar="N",
        help=f"{items} per Ray task (None: {default_task_size})",
    )
    parser.add_argument(
        "--ray-max-retries",
        type=int,
        default=RayOptions.max_retries,
        metavar="N",
        help="Ray's re-runs of a task whose worker or node died",
    )


def ray_options_from_args(args: Any, num_cpus: int = 1) -> RayOptions | None:
    """The :class:`RayOptions` of parsed :func:`add_ray_arguments` options (``None`` without
    ``--ray``); ``num_cpus`` per task."""
    if args.ray is None:
        return None
    return RayOptions(
        address=None if args.ray == LOCAL_RAY else args.ray,
        task_size=args.ray_task_size,
        num_cpus=num_cpus,
        max_retries=args.ray_max_retries,
    )


def _describe(chunk: Sequence[Any]) -> str:
    if isinstance(chunk, range):
        return f"seeds {chunk.start}..{chunk.stop - 1}"
    return f"{len(chunk)} item(s)"


def import_ray() -> Any:
    """The ``ray`` module, or ``RuntimeError`` saying how to install it."""
    try:
        import ray
    except ImportError as err:
        raise RuntimeError(
            f"--ray (RayOptions) needs Ray, which is not installed ({err}): {RAY_EXTRA_HINT}"
        ) from err
    return ray


#: Seconds :func:`check_reachable` waits for a head's port.
CONNECT_TIMEOUT = 5.0


def check_reachable(address: str) -> None:
    """``RuntimeError`` naming ``address`` when it is ``host:port`` and nothing accepts a TCP
    connection there within :data:`CONNECT_TIMEOUT` (Ray itself would retry for minutes);
    other forms (``auto``, ``ray://...``) are left to Ray."""
    host, sep, port = address.rpartition(":")
    if not sep or not host or not port.isdigit() or "/" in address:
        return
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT):
            pass
    except OSError as err:
        raise RuntimeError(
            f"no Ray head answers at {address!r} ({err}); start one there with `ray start "
            f"--head --port {port}` or pass the address it printed (see docs/ray.md)"
        ) from err


def init_ray(address: str | None) -> Any:
    """Connects to the Ray cluster at ``address`` (``None``: starts or joins a local one) unless
    this process is connected already; returns the ``ray`` module. ``RuntimeError`` names the
    address when no cluster answers there."""
    ray = import_ray()
    if ray.is_initialized():
        return ray
    if address is not None:
        check_reachable(address)
    try:
        ray.init(
            address=address,
            logging_level="WARNING",
            configure_logging=True,
            log_to_driver=os.environ.get("MS2_RAY_WORKER_LOGS", "") == "1",
        )
    except ConnectionError as err:
        raise RuntimeError(
            f"cannot connect to a Ray cluster at {address!r} ({err}); start one with "
            "`ray start --head` (see docs/ray.md)"
        ) from err
    return ray


def _is_lost(ray: Any) -> Callable[[BaseException], bool]:
    """Whether an error of ``ray.get`` means the task's work was lost (a dead worker or node, a
    lost object), as opposed to an exception the task raised (``RayTaskError``)."""

    def is_lost(err: BaseException) -> bool:
        return isinstance(err, ray.exceptions.RayError) and not isinstance(
            err, ray.exceptions.RayTaskError
        )

    return is_lost


def ray_chunks(
    items: Sequence[Any],
    function: Callable[..., Sequence[Any]],
    args: tuple[Any, ...],
    options: RayOptions,
    default_task_size: int,
) -> OrderedChunks:
    """:class:`OrderedChunks` over ``items`` whose chunks run as Ray tasks
    ``function(chunk, *args)`` (a module-level function, importable on every node: Ray ships
    it by reference) on the cluster ``options.address``."""
    ray = init_ray(options.address)
    remote = ray.remote(function).options(
        num_cpus=options.num_cpus, max_retries=options.max_retries, retry_exceptions=False
    )
    shared = [ray.put(arg) for arg in args]  # sent once, not with every task
    in_flight = options.in_flight
    if in_flight is None:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        in_flight = max(2, 2 * cpus // options.num_cpus)
    return OrderedChunks(
        items,
        options.task_size or default_task_size,
        lambda chunk: remote.remote(chunk, *shared),
        ray.get,
        in_flight=in_flight,
        max_resubmits=options.max_resubmits,
        is_lost=_is_lost(ray),
        cancel=lambda handle: ray.cancel(handle, force=False),
    )


__all__ = [
    "ChunkLostError",
    "LOCAL_RAY",
    "OrderedChunks",
    "RAY_EXTRA_HINT",
    "RayOptions",
    "add_ray_arguments",
    "check_reachable",
    "import_ray",
    "init_ray",
    "ray_chunks",
    "ray_options_from_args",
]
