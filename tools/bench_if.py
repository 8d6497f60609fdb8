"""Instruction-following benchmark: every policy on a states file, as a Table I (IF column) table plus JSON.

    .venv/bin/python tools/bench_if.py --states tools/data/if/test.jsonl [--json out.json]
    .venv/bin/python tools/bench_if.py if-states --out tools/data/if      # rebuild the states files

Same as `scone-bench if ...` / `scone-bench if-states ...`; see docs/results/instruction_following.md.
"""

from __future__ import annotations

import sys

from scone_bt.instruction_following.cli import main

if __name__ == "__main__":
    argv = sys.argv[1:]
    if not argv or argv[0] not in ("if", "if-states", "-h", "--help"):
        argv = ["if", *argv]
    sys.exit(main(argv))
