"""Which engine runs a batch of tasks: the local process pool (default) or a Ray cluster (`--ray`)."""

from __future__ import annotations

import argparse
import os
from dataclasses import dataclass
from enum import Enum

from scone_bt.errors import DistributedError

__all__ = ["EngineKind", "EngineOptions", "add_engine_arguments", "engine_from_args", "RAY_ADDRESS_FORMS"]

RAY_ADDRESS_FORMS = ("auto", "local", "ray://<host>:<port>")
"""What `--ray` accepts: join the cluster of this machine (else start one), always start a fresh local runtime,
or connect to a remote cluster's Ray Client server (port 10001 by default)."""


class EngineKind(Enum):
    """Where tasks run."""

    LOCAL = "local"  # a process pool on this machine (in-process when workers == 1)
    RAY = "ray"  # tasks on a Ray cluster (started locally or joined)


@dataclass(frozen=True)
class EngineOptions:
    """How to run a batch of independent, seeded tasks.

    Attributes:
        kind: Local process pool or Ray.
        workers: Tasks in flight at once; None: every CPU of this machine (local) or of the cluster (Ray).
        address: Ray only: "auto", "local" or "ray://host:port" (see RAY_ADDRESS_FORMS).
        max_retries: Times a task whose worker process died is run again (an exception raised by the task
            itself is a program error and is never retried).
        rng_seed: Base seed; task i runs with Python's and NumPy's global generators seeded from (rng_seed, i),
            so code that draws from them gives the same result on any worker.
        progress: Description of a progress bar on stderr, or None for no bar.
    """

    kind: EngineKind = EngineKind.LOCAL
    workers: int | None = None
    address: str | None = None
    max_retries: int = 3
    rng_seed: int = 0
    progress: str | None = None

    def __post_init__(self) -> None:
        if self.workers is not None and self.workers < 1:
            raise DistributedError(f"workers must be at least 1, got {self.workers}")
        if self.max_retries < 0:
            raise DistributedError(f"max_retries must be ≥ 0, got {self.max_retries}")
        if self.kind is EngineKind.RAY:
            _check_address(self.address or "auto")

    @property
    def label(self) -> str:
        """Short human description ("local ×2", "ray auto ×4")."""
        n = "all CPUs" if self.workers is None else str(self.workers)
        return f"local ×{n}" if self.kind is EngineKind.LOCAL else f"ray {self.address or 'auto'} ×{n}"

    def local_workers(self) -> int:
        """Worker processes of the local pool."""
        return self.workers if self.workers is not None else max(1, os.cpu_count() or 1)


def _check_address(address: str) -> None:
    if address in ("auto", "local"):
        return
    if address.startswith("ray://"):
        host, _, port = address[len("ray://") :].rpartition(":")
        if host and port.isdigit():
            return
    raise DistributedError(f"--ray {address!r} is not a Ray address; valid: {', '.join(RAY_ADDRESS_FORMS)}")


def add_engine_arguments(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """Add `--ray [ADDRESS]` (no value: auto) to a command that already has its own worker-count option."""
    parser.add_argument(
        "--ray",
        nargs="?",
        const="auto",
        default=None,
        metavar="ADDRESS",
        help="run the tasks on Ray: 'auto' (the default with no value: join this machine's cluster, else start "
        "one), 'local' (start a fresh local runtime) or ray://host:port (one that does not accept a connection within "
        "10 s is a one-line error); without --ray a local process pool runs "
        "them; results are identical either way",
    )


def engine_from_args(
    args: argparse.Namespace, workers: int | None, progress: str | None = None, rng_seed: int = 0
) -> EngineOptions:
    """EngineOptions from `--ray` (see add_engine_arguments) and the command's worker count."""
    address = getattr(args, "ray", None)
    kind = EngineKind.LOCAL if address is None else EngineKind.RAY
    return EngineOptions(kind=kind, workers=workers, address=address, progress=progress, rng_seed=rng_seed)
