"""The episode-speed benchmark; a thin wrapper: it runs ``scone-bench episode`` (scone_bt/benchmarks/episode.py).

.venv/bin/python tools/bench_episode.py --recipes example:hummus
"""

from __future__ import annotations

import sys

from scone_bt.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(["episode", *sys.argv[1:]]))
