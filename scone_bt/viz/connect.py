"""Checking a `--connect` address before streaming: a bad, unreachable or silent viewer is an error within seconds.

rerun's gRPC sink waits about five seconds for an unreachable viewer when it is attached and then keeps retrying
in the background, and an unbounded flush at the end waits forever; so the address is parsed and probed before
the sink is created: a TCP connection (bounded by `timeout_s`), then the opening of an HTTP/2 connection, which
is what gRPC runs on (a viewer answers the client's preface with its SETTINGS frame; bounded by
`handshake_timeout_s`). A peer that accepts connections and never answers, or answers something else, is refused.
"""

from __future__ import annotations

import socket
import ssl
import threading
import time
from urllib.parse import urlsplit

from scone_bt.errors import ConfigError

__all__ = [
    "VIEWER_SCHEMES",
    "DEFAULT_VIEWER_PORT",
    "CONNECT_TIMEOUT_S",
    "HANDSHAKE_TIMEOUT_S",
    "viewer_url",
    "check_viewer_address",
]

CONNECT_TIMEOUT_S = 2.0
"""Longest wait for a TCP connection to the viewer, name resolution included (seconds)."""
HANDSHAKE_TIMEOUT_S = 3.0
"""Longest wait for the viewer's answer to the HTTP/2 (gRPC) connection preface (seconds)."""

# RFC 9113 §3.4: the client preface, then an empty SETTINGS frame; a server's first frame must be SETTINGS.
_H2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])
_H2_SETTINGS = 0x4

VIEWER_SCHEMES = ("rerun", "rerun+http", "rerun+https")
DEFAULT_VIEWER_PORT = 9876
_EXAMPLE = "rerun+http://127.0.0.1:9876/proxy or 127.0.0.1:9876"


def viewer_url(address: str) -> tuple[str, str, int]:
    """Parse `address` (a rerun URL or host:port) into (url, host, port); ConfigError if it is not one."""
    text = address.strip()
    if not text or any(c.isspace() for c in text):
        raise ConfigError(f"--connect {address!r}: not an address; expected e.g. {_EXAMPLE}")
    url = text if "://" in text else f"rerun+http://{text}/proxy"
    try:
        parts = urlsplit(url)
        port = parts.port
    except ValueError as exc:
        raise ConfigError(
            f"--connect {address!r}: not an address ({exc}); expected e.g. {_EXAMPLE}"
        ) from None
    if parts.scheme not in VIEWER_SCHEMES:
        raise ConfigError(
            f"--connect {address!r}: unknown scheme {parts.scheme!r}; valid: {', '.join(VIEWER_SCHEMES)}"
        )
    host = parts.hostname
    if not host:
        raise ConfigError(f"--connect {address!r}: no host; expected e.g. {_EXAMPLE}")
    if port is None:
        if "://" not in text:
            raise ConfigError(f"--connect {address!r}: no port; expected host:port, e.g. {_EXAMPLE}")
        port = DEFAULT_VIEWER_PORT
    if port == 0:
        raise ConfigError(f"--connect {address!r}: port 0 is not a viewer's port")
    return url, host, port


def _handshake(sock: socket.socket, host: str, tls: bool, timeout_s: float) -> str | None:
    """None if the peer answers the HTTP/2 preface with a SETTINGS frame within timeout_s, else why not."""
    deadline = time.monotonic() + timeout_s
    try:
        if tls:
            context = ssl.create_default_context()
            context.set_alpn_protocols(["h2"])
            sock.settimeout(timeout_s)
            sock = context.wrap_socket(sock, server_hostname=host)
        sock.settimeout(max(0.01, deadline - time.monotonic()))
        sock.sendall(_H2_PREFACE)
        header = b""
        while len(header) < 9:  # a frame header: length (3), type (1), flags (1), stream (4)
            sock.settimeout(max(0.01, deadline - time.monotonic()))
            chunk = sock.recv(9 - len(header))
            if not chunk:
                return "it closed the connection without answering; is it a rerun viewer?"
            header += chunk
    except TimeoutError:
        return f"it accepted the connection but did not answer within {timeout_s:g} s"
    except ssl.SSLError as exc:
        return f"TLS failed ({exc.reason or exc})"
    except OSError as exc:
        return exc.strerror or str(exc)
    if header[3] != _H2_SETTINGS:
        return "it answered, but not as a gRPC (HTTP/2) server; is it a rerun viewer?"
    return None


def _probe(
    host: str, port: int, timeout_s: float, handshake_timeout_s: float | None = None, tls: bool = False
) -> str | None:
    """None if a gRPC server answers at host:port (TCP within timeout_s, then the handshake), else why not."""
    result: list[str | None] = []

    def attempt() -> None:
        try:
            with socket.create_connection((host, port), timeout=timeout_s) as sock:
                result.append(
                    None if handshake_timeout_s is None else _handshake(sock, host, tls, handshake_timeout_s)
                )
        except socket.gaierror:
            result.append("the host name does not resolve")
        except ConnectionRefusedError:
            result.append("connection refused: no viewer is listening there")
        except TimeoutError:
            result.append(f"no answer within {timeout_s:g} s")
        except OSError as exc:
            result.append(exc.strerror or str(exc))

    # name resolution has no timeout of its own: bound the whole attempt with a daemon thread
    worker = threading.Thread(target=attempt, name="viewer-probe", daemon=True)
    worker.start()
    worker.join(timeout_s + (handshake_timeout_s or 0.0) + 0.5)
    return result[0] if result else f"no answer within {timeout_s + (handshake_timeout_s or 0.0):g} s"


def check_viewer_address(
    address: str, timeout_s: float = CONNECT_TIMEOUT_S, handshake_timeout_s: float = HANDSHAKE_TIMEOUT_S
) -> str:
    """The rerun URL for `address` once a viewer answers there; ConfigError (one line) within the deadlines if not.

    Args:
        address: A rerun URL (rerun+http://host:port/proxy) or host:port.
        timeout_s: Deadline of the TCP connection, name resolution included (seconds).
        handshake_timeout_s: Deadline of the viewer's answer to the HTTP/2 preface (seconds).
    """
    url, host, port = viewer_url(address)
    tls = urlsplit(url).scheme == "rerun+https"
    why = _probe(host, port, timeout_s, handshake_timeout_s, tls)
    if why is not None:
        raise ConfigError(
            f"--connect {address}: cannot reach a rerun viewer at {host}:{port} ({why}); start one with "
            "`rerun`, or record with --save and open the file later"
        )
    return url
