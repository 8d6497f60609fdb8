"""A short run of the tablet load test: concurrent tablets, zero lost or duplicated answers (scone-bench tablet-load)."""

from scone_bt.study.loadtest import LoadTestOptions, run_load_test


def test_concurrent_tablets_lose_and_duplicate_nothing(tmp_path):
    result = run_load_test(LoadTestOptions(clients=6, duration_s=2.0, rng_seed=1), tmp_path / "load.db")
    assert result.errors == [] and result.unexpected == 0, (result.errors, result.statuses)
    assert result.acknowledged > 0 and result.refused > 0  # contested questionnaires happened
    assert result.lost == 0 and result.duplicated == 0 and result.unacknowledged_stored == 0
    assert result.stored == result.acknowledged
    assert result.latency_ms["state"]["n"] > 0 and "p95" in result.latency_ms["submit"]


def test_out_of_range_options_are_one_line_before_the_server_starts(capsys):
    from scone_bt.cli.bench import main

    for flag, value in [("--think", "-1"), ("--think", "nan"), ("--duration", "0"), ("--clients", "0")]:
        argv = ["tablet-load", "--duration", "1", "--clients", "1", flag, value]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{flag} " in err and "Traceback" not in err


def test_a_client_that_fails_is_a_record_not_a_thread_traceback():
    import time

    from scone_bt.study.loadtest import _run_clients

    # think_s < 0 makes time.sleep raise in the client thread (run_load_test refuses it; called directly here)
    options = LoadTestOptions(clients=1, duration_s=0.3, think_s=-1.0)
    records = _run_clients(9, "token", options, time.time())
    assert [r[0] for r in records if r[0] == "crash"] == ["crash"]
    assert "client 0: ValueError" in next(r[4] for r in records if r[0] == "crash")


def test_a_failed_client_fails_the_run(tmp_path, monkeypatch):
    import concurrent.futures

    import pytest

    from scone_bt.errors import SconeError
    from scone_bt.study import loadtest

    class InThisProcess(
        concurrent.futures.ThreadPoolExecutor
    ):  # the clients in this process, _client patched
        def __init__(self, workers, mp_context=None):
            super().__init__(workers)

    def broken(*args):
        raise RuntimeError("boom")

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", InThisProcess)
    monkeypatch.setattr(loadtest, "_client", broken)
    with pytest.raises(SconeError, match="a client failed.*client 0: RuntimeError: boom"):
        run_load_test(LoadTestOptions(clients=2, duration_s=0.2), tmp_path / "load.db")
