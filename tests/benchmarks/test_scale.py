"""scone-bench scale on a real local Ray runtime: the same physical executions on 1 and 2 workers."""

from __future__ import annotations

import pytest

from scone_bt.benchmarks.scale import run_scale


@pytest.mark.slow
def test_scale_runs_the_same_executions_on_one_and_two_workers():
    import ray

    started_here = not ray.is_initialized()
    try:
        report = run_scale(executions=1, workers=(1, 2), overhead_tasks=10)  # tiny: Ray start-up dominates
    finally:
        if started_here:
            ray.shutdown()  # do not keep a runtime's processes for the rest of the suite
    assert report["identical_results"] == 1
    assert set(report["executions_per_s"]) == {"1", "2"} and all(
        v > 0 for v in report["executions_per_s"].values()
    )
    assert report["speedup"] == pytest.approx(
        report["executions_per_s"]["2"] / report["executions_per_s"]["1"], rel=0.01
    )
    assert report["overhead"]["noop_task_roundtrip_ms"] > 0 and report["machine_ceiling_speedup"] > 0
    assert 0 < report["projection_100_workers"]["speedup"] <= 100


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--arm", "nosuch"], "scone-bench: --arm nosuch: unknown robot; valid: iiwa7, panda\n"),
        (["--workers", "1000"], "scone-bench: --workers 1000: this machine has"),
    ],
)
def test_scale_refuses_a_bad_robot_or_worker_count_before_ray_starts(
    argv, message, capsys, monkeypatch
) -> None:
    import scone_bt.distributed.ray_engine as ray_engine
    from scone_bt.cli.bench import main

    monkeypatch.setattr(ray_engine, "connect_ray", lambda *a, **k: pytest.fail("Ray started"))
    assert main(["scale", *argv]) == 2
    assert capsys.readouterr().err.startswith(message)
