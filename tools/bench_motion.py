"""The motion benchmark; kept as a thin wrapper: it runs ``scone-bench motion`` (see scone_bt/benchmarks/motion.py).

.venv/bin/python tools/bench_motion.py --queries 20
"""

from __future__ import annotations

import sys

from scone_bt.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(["motion", *sys.argv[1:]]))
