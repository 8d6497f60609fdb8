"""The perception benchmark; kept as a thin wrapper: it runs ``scone-bench perception`` (scone_bt/benchmarks/perception.py).

.venv/bin/python tools/bench_perception.py --scenes 3
"""

from __future__ import annotations

import sys

from scone_bt.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(["perception", *sys.argv[1:]]))
