"""Running batches of seeded tasks past one process: a local process pool (default) or a Ray cluster.

    from scone_bt.distributed import EngineKind, EngineOptions, map_tasks
    map_tasks(fn, items, engine=EngineOptions(workers=2))                              # local pool
    map_tasks(fn, items, engine=EngineOptions(EngineKind.RAY, workers=8, address="ray://head:10001"))

Results are identical on either engine and for any worker count; see docs/distributed.md.
"""

from scone_bt.distributed.options import (
    RAY_ADDRESS_FORMS,
    EngineKind,
    EngineOptions,
    add_engine_arguments,
    engine_from_args,
)
from scone_bt.distributed.seeding import task_seed
from scone_bt.distributed.tasks import imap_tasks, map_tasks, start_engine

__all__ = [
    "RAY_ADDRESS_FORMS",
    "EngineKind",
    "EngineOptions",
    "add_engine_arguments",
    "engine_from_args",
    "imap_tasks",
    "map_tasks",
    "start_engine",
    "task_seed",
]
