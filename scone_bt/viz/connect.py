"""Checking a `--connect` address before streaming: a bad or unreachable viewer is an error within seconds.

rerun's gRPC sink waits about five seconds for an unreachable viewer when it is attached and then keeps retrying
in the background, and an unbounded flush at the end waits forever; so the address is parsed and probed with a
plain TCP connection (bounded by `timeout_s`) before the sink is created.
"""

from __future__ import annotations

import socket
import threading
from urllib.parse import urlsplit

from scone_bt.errors import ConfigError

__all__ = ["VIEWER_SCHEMES", "DEFAULT_VIEWER_PORT", "viewer_url", "check_viewer_address"]

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


def _probe(host: str, port: int, timeout_s: float) -> str | None:
    """None if something accepts TCP connections at host:port within timeout_s, else why not."""
    result: list[str | None] = []

    def attempt() -> None:
        try:
            with socket.create_connection((host, port), timeout=timeout_s):
                result.append(None)
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
    worker.join(timeout_s + 0.5)
    return result[0] if result else f"no answer within {timeout_s:g} s"


def check_viewer_address(address: str, timeout_s: float = 2.0) -> str:
    """The rerun URL for `address` once a viewer answers there; ConfigError (one line) within ~timeout_s if not."""
    url, host, port = viewer_url(address)
    why = _probe(host, port, timeout_s)
    if why is not None:
        raise ConfigError(
            f"--connect {address}: cannot reach a rerun viewer at {host}:{port} ({why}); start one with "
            "`rerun`, or record with --save and open the file later"
        )
    return url
