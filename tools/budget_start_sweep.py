"""Where the failure budget's threshold starts, and how fast it moves: τ₀ = 1 − kα and η, swept on the replay.

The shipped gate starts at τ₀ = 1 − 3α with step η = 0.05 (`gate.budget`), chosen before the heft probe and on a
replay that counted undetected targets and plans that do not exist as failed attempts (docs/results/gate.md). On
today's replay the robot spends about half its budget at α = 0.15 (0.077 of its attempts fail). This replays the
shipped gate (the probe and the strict promise on, cold, censored, warm-up 20) with other ``start_margin`` k and
``step`` η, from every ``--step``-th row of each stream as `benchmarks.gate.results_over_starts` does (each start a
new cold robot), and prints one JSON line per (k, η) with, for each α: the failure and help rates' mean and largest
over the starts, and the largest excess of failures over α × attempts in any stream of any start
(``max_excess_failures``).

    PYTHONPATH=$PWD python tools/budget_start_sweep.py --datasets tools/data/sc_probe \\
        --margins 3,4,5,6 --steps 0.02,0.05 --alphas 0.05,0.1,0.15
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def _floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


def main() -> None:
    from scone_bt.benchmarks.gate import replay_args, results_over_starts
    from scone_bt.benchmarks.replay_rates import pooled_rates
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.gate.budget import BudgetOptions
    from scone_bt.gate.probe import ProbeOptions

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", default="tools/data/sc_probe")
    ap.add_argument("--margins", default="3,4,5,6", help="comma-separated k of τ₀ = 1 − kα")
    ap.add_argument("--steps", default="0.02,0.05", help="comma-separated η")
    ap.add_argument("--alphas", default="0.05,0.1,0.15")
    ap.add_argument("--step", type=int, default=10, help="start a cold robot at every this many rows")
    a = ap.parse_args()
    args = replay_args(a.datasets)
    streams = load_streams(args, oracle=False)
    for margin in _floats(a.margins):
        for eta in _floats(a.steps):
            t0 = time.time()
            line: dict = {"start_margin": margin, "step": eta}
            # stream_results hands it to each replay (replay_rules keeps its own α and allowance)
            args.budget = BudgetOptions(start_margin=margin, step=eta)
            for alpha in _floats(a.alphas):
                rates = [
                    pooled_rates(results)
                    for _, results in results_over_starts(
                        streams, a.step, "physical", alpha, args, probe=ProbeOptions()
                    )
                ]
                failure = [r["attempt_failure_rate"] for r in rates]
                help_ = [r["help_rate"] for r in rates]
                line[f"{alpha:g}"] = {
                    "attempt_failure_rate_mean": round(float(np.mean(failure)), 4),
                    "attempt_failure_rate_max": round(max(failure), 4),
                    "help_rate_mean": round(float(np.mean(help_)), 4),
                    "help_rate_max": round(max(help_), 4),
                    "max_excess_failures": round(max(r["max_excess_failures"] for r in rates), 2),
                }
            line["wall_s"] = round(time.time() - t0, 1)
            print(json.dumps(line), flush=True)


if __name__ == "__main__":
    main()
