"""A benchmark's JSON report: printed, and written whole to ``--json FILE`` (strict JSON).

One rule for that file, before the benchmark runs (`cli.bench.check_report_path`) and at the write (`emit_report`): not a
folder, device or input of the run; an existing report may be replaced (benchmarks are re-run into
docs/results/*.json); any other existing file only with --force; a YAML file never (`check_not_yaml`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

from scone_bt.checks import check_not_yaml, check_output_file, is_output_kind, write_atomic
from scone_bt.strict_json import dumps

__all__ = ["check_report_file", "emit_report"]


def _is_report_file(path: Path) -> bool:
    return is_output_kind(path, "report")


def check_report_file(
    path: Path,
    flag: str = "--json",
    *,
    inputs: Mapping[str, Iterable[Path | str]] | None = None,
    force: bool = False,
) -> Path:
    """Refuse a report FILE that would destroy something (one line naming `flag`): a folder, a device, one of
    `inputs` or an unwritable folder (even with `force`), then a YAML file (even with `force`), then an existing
    file that is not a benchmark report (a JSON object with one of `checks.REPORT_KEYS`) unless `force`."""
    # In this order, so each message is the one that holds even with --force: an input of the run (naming its
    # flag), a YAML file, then a file that is not a report (which --force may replace).
    check_output_file(path, flag, kind="report", inputs=inputs, force=True)
    check_not_yaml(path, flag, "a JSON report", ".json", ours=_is_report_file)
    return check_output_file(path, flag, kind="report", inputs=inputs, force=force)


def emit_report(
    report: object,
    json_path: str | Path | None,
    indent: int = 2,
    make_parent: bool = False,
    force: bool = False,
) -> None:
    """Print a benchmark's JSON report and, with ``--json FILE``, write the same text there (strict JSON).

    The file is written whole or not at all (a temporary file renamed over it); an existing file that is not a
    benchmark report is not replaced unless `force` (pass the command's --force), a YAML file never
    (`check_report_file`; scone-bench checks this before the benchmark runs, too).
    """
    text = dumps(report, indent=indent)
    print(text)
    if json_path:
        path = check_report_file(Path(json_path), force=force)
        if make_parent:  # after the check: a file where a folder should be is one line, not a traceback
            path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, text + "\n")
