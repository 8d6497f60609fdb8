"""--connect: a bad or unreachable address is an error within seconds; a viewer that goes away mid-run does not
stop the recording (the real rerun viewer, headless: `rerun --serve-grpc`)."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.viz.connect import check_viewer_address, viewer_url
from scone_bt.viz.recorder import Recorder
from scone_bt.viz.snapshot import TickSnapshot

RERUN = Path(sys.executable).parent / "rerun"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    ("address", "expected"),
    [
        ("not-an-address", "no port"),
        ("", "not an address"),
        ("127.0.0.1:99999", "not an address"),
        ("127.0.0.1:0", "port 0"),
        ("ftp://127.0.0.1:9876", "unknown scheme .ftp."),
        ("rerun+http://:9876/proxy", "no host"),
        ("has space:1", "not an address"),
    ],
)
def test_malformed_addresses(address, expected):
    with pytest.raises(ConfigError, match=expected):
        viewer_url(address)


def test_address_forms():
    assert viewer_url("127.0.0.1:9876") == ("rerun+http://127.0.0.1:9876/proxy", "127.0.0.1", 9876)
    assert viewer_url("rerun+http://localhost/proxy")[2] == 9876


def _in_thread(fn, timeout: float = 60.0):  # noqa: ANN001, ANN202
    out: list = []

    def run() -> None:
        try:
            out.append(("ok", fn()))
        except Exception as exc:  # noqa: BLE001 - handed back to the test
            out.append(("error", exc))

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(timeout)
    assert not worker.is_alive(), "hangs"
    return out[0]


def test_unreachable_viewer_is_an_error_not_a_hang():
    port = _free_port()
    kind, value = _in_thread(lambda: check_viewer_address(f"127.0.0.1:{port}", timeout_s=1.0))
    assert kind == "error" and "cannot reach a rerun viewer" in str(value)
    kind, value = _in_thread(lambda: Recorder(connect=f"rerun+http://127.0.0.1:{port}/proxy"))
    assert kind == "error" and isinstance(value, ConfigError)
    kind, value = _in_thread(lambda: check_viewer_address("rerun+http://no-such-host.invalid:9876/proxy"))
    assert kind == "error" and "cannot reach" in str(value)


@pytest.fixture
def viewer():
    """A real rerun gRPC server (what a running viewer listens with), headless."""
    if not RERUN.is_file():
        pytest.skip("rerun CLI not installed beside Python")
    port = _free_port()
    proc = subprocess.Popen(
        [str(RERUN), "--serve-grpc", "--port", str(port)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            time.sleep(0.1)
    yield proc, port
    proc.kill()
    proc.wait(10)


def _tick(i: int) -> TickSnapshot:
    return TickSnapshot(
        tick=i,
        sim_time=0.1 * i,
        executed_q=np.full(7, 0.01 * i),
        counters={"successes": i // 10},
        log_lines=[f"tick {i}"],
    )


def test_a_viewer_that_goes_away_does_not_stop_the_run(viewer, tmp_path):
    proc, port = viewer
    rec = Recorder(save=tmp_path / "run.rrd", connect=f"127.0.0.1:{port}")
    for i in range(50):
        rec.log_tick(_tick(i))
    assert rec.flush()
    proc.kill()  # the viewer window is closed mid-run
    proc.wait(10)

    def rest_of_the_run() -> int:
        for i in range(50, 400):
            rec.log_tick(_tick(i))
        rec.close()
        return rec.ticks_logged

    kind, value = _in_thread(rest_of_the_run)
    assert (kind, value) == ("ok", 400)
    assert (tmp_path / "run.rrd").stat().st_size > 0  # the file sink kept everything
