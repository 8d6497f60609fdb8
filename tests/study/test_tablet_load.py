"""A short run of the tablet load test: concurrent tablets, zero lost or duplicated answers (scone-bench tablet-load)."""

from scone_bt.study.loadtest import LoadTestOptions, run_load_test


def test_concurrent_tablets_lose_and_duplicate_nothing(tmp_path):
    result = run_load_test(LoadTestOptions(clients=6, duration_s=2.0, rng_seed=1), tmp_path / "load.db")
    assert result.errors == [] and result.unexpected == 0, (result.errors, result.statuses)
    assert result.acknowledged > 0 and result.refused > 0  # contested questionnaires happened
    assert result.lost == 0 and result.duplicated == 0 and result.unacknowledged_stored == 0
    assert result.stored == result.acknowledged
    assert result.latency_ms["state"]["n"] > 0 and "p95" in result.latency_ms["submit"]
