"""A real local Ray runtime (2 CPUs, no dashboard), started once for the tests that need it."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

# The task functions live in a plain module so that spawned pool workers can import them (they inherit sys.path).
sys.path.insert(0, str(Path(__file__).parent))


@pytest.fixture(scope="session")
def ray_runtime():
    import engine_tasks
    import ray
    import ray.cloudpickle

    from scone_bt.distributed.ray_engine import connect_ray

    ray.cloudpickle.register_pickle_by_value(engine_tasks)  # Ray workers do not see tests/ on their sys.path
    connect_ray("local", num_cpus=2)
    yield ray
    ray.shutdown()
