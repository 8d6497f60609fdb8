"""A benchmark's JSON report: printed, and written whole to ``--json FILE`` (strict JSON)."""

from __future__ import annotations

from pathlib import Path

from scone_bt.checks import check_output_file, write_atomic
from scone_bt.strict_json import dumps

__all__ = ["emit_report"]


def emit_report(
    report: object,
    json_path: str | Path | None,
    indent: int = 2,
    make_parent: bool = False,
    force: bool = False,
) -> None:
    """Print a benchmark's JSON report and, with ``--json FILE``, write the same text there (strict JSON).

    The file is written whole or not at all (a temporary file renamed over it); an existing file that is not JSON
    is not replaced unless `force` (scone-bench checks this before the benchmark runs, too).
    """
    text = dumps(report, indent=indent)
    print(text)
    if json_path:
        path = Path(json_path)
        if make_parent:
            path.parent.mkdir(parents=True, exist_ok=True)
        check_output_file(path, "--json", kind="json", force=force)
        write_atomic(path, text + "\n")
