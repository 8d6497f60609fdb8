"""Fuzz tests: every run counts the inputs tried per loader and endpoint and prints them in the summary."""

from __future__ import annotations

import pytest

_COUNTS: dict[str, int] = {}


@pytest.fixture(scope="session")
def fuzz_counts() -> dict[str, int]:
    """Inputs tried per loader / endpoint in this session (docs/reliability.md lists them)."""
    return _COUNTS


def pytest_terminal_summary(terminalreporter) -> None:  # noqa: ANN001 - pytest hook
    if _COUNTS:
        line = ", ".join(f"{k} {v}" for k, v in sorted(_COUNTS.items()))
        terminalreporter.write_line(f"fuzzed inputs: {line}")
