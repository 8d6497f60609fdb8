"""`sc generate` progress: a plain tqdm bar; its notes go to stderr, and --no-progress silences both."""

from __future__ import annotations

from scone_bt.benchmarks.progress import progress_bar
from scone_bt.benchmarks.self_confidence.batch import _note


def test_notes_go_to_stderr_above_the_bar(capsys):
    with progress_bar(3, "executions", quiet=False, unit="run") as bar:
        _note(bar, "resuming: 2 executions already recorded, 3 to run")
        bar.update(3)
    out, err = capsys.readouterr()
    assert out == "" and "resuming: 2 executions already recorded, 3 to run\n" in err


def test_no_progress_prints_nothing_at_all(capsys):
    with progress_bar(3, "executions", quiet=True, unit="run") as bar:
        _note(bar, "--max-minutes reached: stopping (finished rows are saved)")
        bar.update(3)
    assert capsys.readouterr() == ("", "")
