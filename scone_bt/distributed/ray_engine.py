"""The Ray engine (the only module that imports ray): start or join a cluster and run seeded tasks on it.

Each task is a Ray task with `max_retries` (Ray re-runs a task whose worker process died) and no retry on
exceptions (those are program errors). At most `workers` tasks are in flight, so one local runtime serves any
worker count, and results are keyed by task index: a task is reported exactly once even if Ray ran it twice.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from scone_bt.distributed.options import RAY_ADDRESS_FORMS, EngineOptions
from scone_bt.distributed.seeding import _NO_SHARED, run_seeded
from scone_bt.errors import DistributedError

__all__ = ["RAY_CONNECT_TIMEOUT_S", "connect_ray", "cluster_cpus", "imap_ray", "shutdown_ray"]

RAY_CONNECT_TIMEOUT_S = 10.0
"""Deadline for a ray://host:port cluster to accept a TCP connection (name resolution included), seconds; checked
before ray.init, whose client retries for much longer."""


def _probe_ray_client(address: str, timeout_s: float = RAY_CONNECT_TIMEOUT_S) -> None:
    """DistributedError (one line) unless something accepts TCP connections at a ray:// address within timeout_s."""
    import socket
    import threading

    host, _, port = address[len("ray://") :].rpartition(":")
    why: list[str | None] = []

    def attempt() -> None:
        try:
            with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s):
                why.append(None)
        except OSError as exc:
            why.append(exc.strerror or str(exc) or type(exc).__name__)

    worker = threading.Thread(target=attempt, name="ray-probe", daemon=True)  # resolution has no timeout
    worker.start()
    worker.join(timeout_s + 0.5)
    reason = why[0] if why else f"no answer within {timeout_s:g} s"
    if reason is not None:
        raise DistributedError(f"cannot reach a Ray cluster at {address!r}: {reason}")


# Workers inherit these: one BLAS/OpenMP thread per task (parallelism comes from tasks), no downloads.
_WORKER_ENV = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "TOKENIZERS_PARALLELISM": "false",
    "HF_HUB_OFFLINE": "1",
    "TRANSFORMERS_OFFLINE": "1",
}


def _quiet_ray() -> None:
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no usage reports leave the machine
    os.environ.setdefault("RAY_DEDUP_LOGS", "0")


def connect_ray(address: str | None = "auto", num_cpus: int | None = None) -> str:
    """Join or start a Ray cluster (no-op if this process is already connected); returns what it did.

    Args:
        address: "auto": the cluster named by RAY_ADDRESS or started on this machine by `ray start`, else a new
            local runtime; "local": always a new local runtime; "ray://host:port": a remote cluster (Ray Client).
        num_cpus: CPUs of a newly started local runtime (None: all of this machine's).

    Raises:
        DistributedError: the cluster cannot be reached.
    """
    from scone_bt.extras import require

    require("fleet", "running on a Ray cluster", ("ray",))
    _quiet_ray()
    import ray

    if ray.is_initialized():
        return "already connected"
    common: dict[str, Any] = {
        "include_dashboard": False,
        "log_to_driver": False,
        "logging_level": "ERROR",
        "runtime_env": {"env_vars": {k: os.environ.get(k, v) for k, v in _WORKER_ENV.items()}},
    }
    address = address or "auto"
    if address.startswith("ray://"):
        _probe_ray_client(address)
    try:
        if address == "auto":
            try:
                ray.init(address="auto", **common)
                return "joined the cluster of this machine"
            except (ConnectionError, RuntimeError, ValueError):
                pass  # no cluster running here: start one, as documented
        if address in ("auto", "local"):
            ray.init(num_cpus=num_cpus, **common)
            return f"started a local Ray runtime with {num_cpus or os.cpu_count()} CPUs"
        ray.init(address=address, **common)
        return f"connected to {address}"
    except Exception as exc:  # Ray raises many types (ConnectionError, grpc errors, TimeoutError)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise DistributedError(
            f"cannot reach a Ray cluster at {address!r}: {first}; valid --ray values: {', '.join(RAY_ADDRESS_FORMS)}"
        ) from None


def cluster_cpus() -> int:
    """CPUs the connected cluster offers (all nodes)."""
    import ray

    return max(1, int(ray.cluster_resources().get("CPU", 1)))


def shutdown_ray() -> None:
    """Disconnect (and stop a runtime this process started)."""
    import ray

    if ray.is_initialized():
        ray.shutdown()


def imap_ray(
    fn: Callable[..., Any], items: Sequence[Any], options: EngineOptions, shared: Any = _NO_SHARED
) -> Iterator[tuple[int, Any]]:
    """Yield (index, fn(items[index])) as Ray tasks finish, each index exactly once."""
    import ray
    from ray.exceptions import RayTaskError

    connect_ray(options.address, options.workers)
    workers = options.workers or cluster_cpus()
    task = ray.remote(run_seeded).options(num_cpus=1, max_retries=options.max_retries, retry_exceptions=False)
    fn_ref = ray.put(fn)  # shipped once, not once per task
    shared_ref = shared if shared is _NO_SHARED else ray.put(shared)
    pending: dict[Any, int] = {}
    next_index = 0
    reported: set[int] = set()
    try:
        while next_index < len(items) or pending:
            while next_index < len(items) and len(pending) < workers:
                args = (fn_ref, next_index, items[next_index], options.rng_seed)
                ref = task.remote(*args) if shared is _NO_SHARED else task.remote(*args, shared_ref)
                pending[ref] = next_index
                next_index += 1
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                i = pending.pop(ref)
                try:
                    value = ray.get(ref)
                except RayTaskError as exc:
                    cause = exc.cause if isinstance(getattr(exc, "cause", None), BaseException) else None
                    if cause is not None:
                        raise cause from None  # the task's own error, e.g. a SconeError with its one-line message
                    raise
                except (
                    ray.exceptions.RayError
                ) as exc:  # worker died more than max_retries times, node lost, ...
                    raise DistributedError(
                        f"task {i} failed on Ray after {options.max_retries} retries: {type(exc).__name__}"
                    ) from None
                if i not in reported:
                    reported.add(i)
                    yield i, value
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
