"""A headless episode without --save, --viewer or --connect never imports rerun (issue 29: start-up)."""

from __future__ import annotations

import subprocess
import sys


def test_a_headless_recorder_does_not_import_rerun() -> None:
    code = (
        "import sys\n"
        "from scone_bt.episode import EpisodeOptions\n"
        "from scone_bt.episode.runner import _make_recorder\n"
        "r = _make_recorder(EpisodeOptions())\n"
        "print(type(r).__name__, 'rerun' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["NullRecorder", "False"], out.stdout + out.stderr
