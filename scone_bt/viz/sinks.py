"""Where a recording goes: a `.rrd` file, a live viewer, or both, each on its own rerun stream.

One stream per kind of sink, under one recording id: a stalled viewer is dropped without touching the file
(rerun can only replace a stream's sinks all at once, which would start the file again). The drawers log through
`Sinks.rec`, which routes to whichever streams are still attached.
"""

from __future__ import annotations

import atexit
import logging
import shutil
import sys
import threading
import time
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rerun as rr

from scone_bt.errors import ConfigError
from scone_bt.viz import paths as P
from scone_bt.viz.blueprint import default_blueprint
from scone_bt.viz.connect import check_viewer_address
from scone_bt.viz.save import unfinished_path

__all__ = [
    "APPLICATION_ID",
    "STREAM_FLUSH_TIMEOUT_S",
    "VIEWER_CHECK_PERIOD_S",
    "VIEWER_STALL_TIMEOUT_S",
    "Sinks",
]

APPLICATION_ID = "scone_bt"
STREAM_FLUSH_TIMEOUT_S = 3.0
"""Longest wait for a live viewer to take the buffered data at close (seconds); a gone viewer costs this once."""
VIEWER_CHECK_PERIOD_S = 2.0
"""How often (wall seconds) a live viewer is asked to take what was logged so far."""
VIEWER_STALL_TIMEOUT_S = 5.0
"""A live viewer that has not taken the data logged so far within this many seconds is dropped (the run goes on)."""

_log = logging.getLogger(__name__)


def _set_sinks(stream: Any, sinks: Sequence[Any], blueprint: Any) -> None:
    """``stream.set_sinks(*sinks, default_blueprint=blueprint)`` without rerun 0.41's leak of the blueprint stream.

    rerun builds the blueprint in a stream of its own whose memory sink and stream hold each other: it is never
    freed, and its two threads (batcher and sink) outlived every recording, four a recording with the default
    blueprint (`scone-bench soak --record`). The same steps as `rerun.sinks.set_sinks`, then that stream is
    disconnected once its contents are handed over, which breaks the cycle (the file keeps the blueprint).
    """
    from rerun import bindings
    from rerun.recording_stream import RecordingStream

    blueprint_stream = RecordingStream._from_native(
        bindings.new_blueprint(
            application_id=APPLICATION_ID, make_default=False, make_thread_default=False, default_enabled=True
        )
    )
    blueprint_stream.set_time("blueprint", sequence=0)
    blueprint.to_blueprint()._log_to_stream(blueprint_stream)
    storage = blueprint_stream.memory_recording().storage
    bindings.set_sinks(list(sinks), default_blueprint=storage, recording=stream.to_native())
    blueprint_stream.disconnect()


def _release_closed_streams() -> None:
    """Free the native side of recording streams no Python object holds any more (their threads with it).

    rerun drops a stream's native half only in this sweep (`rerun.init` runs it too); without it the batcher and
    sink threads of every closed recording stayed. It flushes what it frees without a deadline, so it runs only
    for recorders that never streamed to a viewer (a stalled viewer's stream would hold it forever).
    """
    from rerun import bindings

    bindings.flush_and_cleanup_orphaned_recordings()


class _Nowhere:
    """A stream that takes everything and keeps nothing (a viewer-only recording whose viewer was dropped)."""

    def log(self, *args: Any, **kwargs: Any) -> None:
        pass

    send_columns = set_time = log

    def flush(self, **kwargs: Any) -> None:
        pass

    def disconnect(self) -> None:
        pass


class _Tee:
    """The file stream and the viewer stream as one: every call goes to both (each has its own sinks, so the
    viewer's can be dropped without touching the file's)."""

    def __init__(self, *streams: Any) -> None:
        self.streams = streams

    def log(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.log(*args, **kwargs)

    def send_columns(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.send_columns(*args, **kwargs)

    def set_time(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.set_time(*args, **kwargs)


_SHUTDOWN_BOUNDED = False


def _bound_rerun_shutdown() -> None:
    """rerun's exit handler flushes every stream without a deadline: with a stalled viewer it would never return.

    It is replaced by one that waits at most STREAM_FLUSH_TIMEOUT_S (files are flushed by `Sinks.close`).
    """
    global _SHUTDOWN_BOUNDED
    if _SHUTDOWN_BOUNDED:
        return
    _SHUTDOWN_BOUNDED = True
    rr.unregister_shutdown()

    def bounded() -> None:
        worker = threading.Thread(target=rr.rerun_shutdown, name="rerun-shutdown", daemon=True)
        worker.start()
        worker.join(STREAM_FLUSH_TIMEOUT_S)

    atexit.register(bounded)


class Sinks:
    """The recording's streams: a file, a spawned viewer and/or a running viewer (see `Recorder` for the args).

    Attributes:
        rec: Where log calls go now: the file and/or the viewer stream (nowhere once closed).
        now: Simulated time of the tick being logged, seconds.
        tick: The tick being logged.
        stream_error: Why the live viewer stopped taking data (None while it does, or without one).
        saved_to: Where the recording is once closed (`save`, or `unfinished_path(save)` after a run ended early).
    """

    def __init__(
        self,
        save: Path | str | None,
        spawn_viewer: bool,
        connect: str | None,
        recording_id: str | None,
        spawn_port: int,
    ) -> None:
        self.save_path = Path(save) if save is not None else None
        self.recording_id = recording_id or str(uuid.uuid4())
        # Checked first: a bad, unreachable or silent address fails here, within seconds, before a file is begun.
        connect_url = check_viewer_address(connect) if connect is not None else None
        self._file_rec: Any = None
        self._view_rec: Any = None
        blueprint = default_blueprint()
        urls: list[str] = []
        if spawn_viewer or connect is not None:
            self._view_rec = self._stream()
        if spawn_viewer:
            rr.spawn(
                port=spawn_port, connect=False, executable_path=_viewer_executable(), recording=self._view_rec
            )
            urls.append(f"rerun+http://127.0.0.1:{spawn_port}/proxy")
        if connect_url is not None and connect_url not in urls:  # rerun refuses two sinks to one address
            urls.append(connect_url)
        self._viewer_urls = tuple(urls)
        # The flag a stalled viewer is reported under: the one the user gave.
        self._viewer_flag = "--connect" if connect is not None else "--viewer"
        if self._view_rec is not None:  # the viewer first: if it fails, no file was begun
            self._attach_viewer(blueprint)
        self._sink_path: Path | None = None
        self.saved_to: Path | None = None
        if self.save_path is not None:
            from scone_bt.files import temporary_beside

            self.save_path.parent.mkdir(parents=True, exist_ok=True)
            self._sink_path = temporary_beside(self.save_path, ".rrd")
            self._file_rec = self._stream()
            _set_sinks(self._file_rec, [rr.FileSink(str(self._sink_path))], blueprint)
        self.rec: Any = self._routing()
        self._viewer_checked_at = time.monotonic()
        self.stream_error: str | None = None
        self.now = 0.0
        self.tick = 0

    @property
    def viewer_attached(self) -> bool:
        """Whether a live viewer is still being streamed to (False without one, or once it was dropped)."""
        return self._view_rec is not None

    def set_time(self, tick: int, sim_time: float) -> None:
        """Log what follows at this tick and simulated time (seconds)."""
        self.now, self.tick = float(sim_time), int(tick)
        self.rec.set_time(P.TICK, sequence=self.tick)
        self.rec.set_time(P.SIM_TIME, duration=float(sim_time))

    def check_viewer_now_and_then(self) -> None:
        """Every VIEWER_CHECK_PERIOD_S, ask the live viewer to take what was logged (dropping one that stalls)."""
        if self._view_rec is not None and time.monotonic() - self._viewer_checked_at >= VIEWER_CHECK_PERIOD_S:
            self._check_viewer(VIEWER_STALL_TIMEOUT_S)

    def flush(self, timeout_s: float | None = None) -> bool:
        """Push everything logged so far to the sinks; False if a viewer did not take it within timeout_s."""
        ok = self._check_viewer(STREAM_FLUSH_TIMEOUT_S if timeout_s is None else timeout_s)
        if self._file_rec is not None:
            self._file_rec.flush(timeout_sec=1e38)
        return ok

    def close(self, complete: bool) -> None:
        """Flush, disconnect the viewer (bounded) and put the file in place (`Recorder.close`)."""
        self.flush()
        if self._view_rec is not None:
            # Disconnecting waits for the viewer without a deadline of its own: bounded here, on a worker thread.
            view = self._view_rec
            worker = threading.Thread(target=view.disconnect, name="rerun-viewer-close", daemon=True)
            worker.start()
            worker.join(STREAM_FLUSH_TIMEOUT_S)
            if worker.is_alive():
                self._view_rec = view  # reported (and left to the bounded exit) by _drop_viewer
                self._drop_viewer("disconnecting timed out", STREAM_FLUSH_TIMEOUT_S, disconnect=False)
            self._view_rec = None
        if self._file_rec is not None:
            self._file_rec.disconnect()
            self.saved_to = self._put_in_place(complete)
        self.rec = _Nowhere()
        self._file_rec = None  # the last reference: the stream is an orphan rerun can free
        if not self._viewer_urls:
            _release_closed_streams()

    def _put_in_place(self, complete: bool) -> Path:
        """Rename the finished file to `save` (or, for a run that ended early, beside an existing one)."""
        from scone_bt.files import replace_with

        assert self.save_path is not None and self._sink_path is not None
        target = self.save_path
        if not complete and target.exists():
            target = unfinished_path(target)
        replace_with(target, self._sink_path)
        return target

    def _stream(self) -> Any:
        rec = rr.RecordingStream(APPLICATION_ID, recording_id=self.recording_id)
        rec.set_log_tick_enabled(False)  # our own `tick` timeline is the one that matters
        return rec

    def _routing(self) -> Any:
        """Where log calls go: the file and/or the viewer stream."""
        streams = [r for r in (self._file_rec, self._view_rec) if r is not None]
        if not streams:
            return _Nowhere()
        return streams[0] if len(streams) == 1 else _Tee(*streams)

    def _attach_viewer(self, blueprint: Any) -> None:
        """Give the viewer stream its gRPC sinks and the blueprint, within VIEWER_STALL_TIMEOUT_S.

        Sending the blueprint waits until the viewer took it, without a deadline: a peer that answers the
        handshake and then reads nothing would hold the robot before its first decision. So it runs on a
        worker thread, and a viewer that has not taken it in time is refused (ConfigError, one line).
        """
        sinks = [rr.GrpcSink(url) for url in self._viewer_urls]
        failed: list[BaseException] = []

        def attach() -> None:
            try:
                _set_sinks(self._view_rec, sinks, blueprint)
            except Exception as exc:  # noqa: BLE001 - re-raised on the caller's thread
                failed.append(exc)

        worker = threading.Thread(target=attach, name="rerun-viewer-attach", daemon=True)
        worker.start()
        worker.join(VIEWER_STALL_TIMEOUT_S)
        if worker.is_alive():
            self._view_rec = None
            _bound_rerun_shutdown()  # the stuck stream must not hold the process at exit either
            raise ConfigError(
                f"{self._viewer_flag} {', '.join(self._viewer_urls)}: the viewer accepted the connection but did not take "
                f"the recording's first data within {VIEWER_STALL_TIMEOUT_S:g} s; is it a rerun viewer that "
                "responds? Record with --save and open the file later"
            )
        if failed:
            raise ConfigError(f"rerun viewer: {' '.join(str(failed[0]).split())}") from None

    def _check_viewer(self, timeout_s: float) -> bool:
        """Whether the live viewer took everything within timeout_s; if not it is dropped (True without one)."""
        self._viewer_checked_at = time.monotonic()
        if self._view_rec is None:
            return True
        try:
            self._view_rec.flush(timeout_sec=timeout_s)
        except RuntimeError as exc:  # rerun reports a gRPC sink that did not take the data this way
            self._drop_viewer(" ".join(str(exc).split()) or "flush timed out", timeout_s)
            return False
        return True

    def _drop_viewer(self, why: str, timeout_s: float, disconnect: bool = True) -> None:
        """Stop streaming to a viewer that stalled or went away; the recording file (if any) goes on."""
        view, self._view_rec = self._view_rec, None
        self.stream_error = why
        self.rec = self._routing()
        _bound_rerun_shutdown()
        if disconnect:  # it flushes without a deadline: a stalled viewer would hold it forever, so not here
            threading.Thread(target=view.disconnect, name="rerun-viewer-drop", daemon=True).start()
        _log.warning(
            "the live viewer at %s did not take the data within %g s (%s); it was dropped and the episode goes "
            "on%s",
            ", ".join(self._viewer_urls),
            timeout_s,
            why,
            f" (still recording to {self.save_path})" if self.save_path is not None else "",
        )


def _viewer_executable() -> str:
    """The `rerun` viewer beside this interpreter (a venv's scripts need not be on PATH), else from PATH."""
    beside = Path(sys.executable).parent / "rerun"
    found = str(beside) if beside.is_file() else shutil.which("rerun")
    if found is None:
        raise ConfigError(
            "cannot spawn the rerun viewer: no 'rerun' executable beside Python or on PATH (pip install rerun-sdk)"
        )
    return found
