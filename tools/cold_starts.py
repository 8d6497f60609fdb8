"""Cold starts from many points of each stream: how often the strict robot ends up asking for everything.

`scone-bench gate` replays each stream from its first row, so each of its figures rests on one cold start per
stream. This replays every stream from every ``--step``-th row as well (the stream rotated: the rows before the
start are appended after its end), each a new cold robot (κ̂ with no outcome, the budget's counts at zero, seeded as
`scone-bench gate` seeds it), as `benchmarks.gate.results_over_starts` replays the shipped gate (the probe and the strict
promise on, warm-up 20). One JSON line per ``--feel-allowance`` (`gate.probe.ProbeOptions.feel_allowance`):

- ``cold_starts``: streams × starts; ``asked_for_everything``: those whose robot attempted nothing after the
  warm-up (every scored decision asked or set back), with their stream and start in ``which``;
- ``help_rate_mean``: the mean over cold starts of each one's help rate; ``attempt_failure_rate``: failures over
  attempts pooled over all of them.

    PYTHONPATH=$PWD python tools/cold_starts.py --datasets tools/data/sc_probe --step 10 --feel-allowance 1,2
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def main() -> None:
    from scone_bt.benchmarks.gate import replay_args, results_over_starts
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.config.tree_parameters import TREE_DEFAULTS
    from scone_bt.gate.probe import ProbeOptions

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", default="tools/data/sc_probe")
    ap.add_argument("--step", type=int, default=10, help="start a cold robot at every this many rows")
    ap.add_argument("--alpha", type=float, default=TREE_DEFAULTS.target_failure_rate)
    ap.add_argument(
        "--feel-allowance", default="2", help="comma-separated ProbeOptions.feel_allowance values"
    )
    a = ap.parse_args()
    if a.step < 1:
        ap.error(f"--step must be ≥ 1, got {a.step}")
    args = replay_args(a.datasets)
    streams = load_streams(args, oracle=False)
    for allowance in (float(x) for x in a.feel_allowance.split(",")):
        t0 = time.time()
        probe = ProbeOptions(feel_allowance=allowance)
        which, helps, failures, attempts = [], [], 0, 0
        for start, results in results_over_starts(streams, a.step, "physical", a.alpha, args, probe=probe):
            for name, r in zip(streams.names, results, strict=True):
                helps.append(1.0 - r.attempts / r.decisions)
                failures, attempts = failures + r.failures, attempts + r.attempts
                if r.attempts == 0:
                    which.append(f"{name}@{start}")
        line = {
            "datasets": a.datasets,
            "alpha": a.alpha,
            "feel_allowance": allowance,
            "step": a.step,
            "cold_starts": len(helps),
            "asked_for_everything": len(which),
            "which": which,
            "help_rate_mean": round(float(np.mean(helps)), 4),
            "attempt_failure_rate": round(failures / attempts, 4) if attempts else None,
            "wall_s": round(time.time() - t0, 1),
        }
        print(json.dumps(line), flush=True)


if __name__ == "__main__":
    main()
