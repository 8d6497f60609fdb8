"""Sweep the heft probe's band over target failure rates on datasets with probe readings (docs/results/probe.md §5).

Each configuration is replayed as ``scone-bench gate`` replays the tree's gate (cold, censored, warm-up 20, the
strict credit rule on unless ``allowance`` is null), with `scone_bt.benchmarks.gate.stream_results`; one JSON line
per (configuration, α). A configuration is a `ProbeOptions` mapping (``below``, ``above``, ``credit``,
``full_band_at``, ``sure_traction``, …), ``{"below": null}`` for no probe, plus ``allowance`` (the strict rule's, default 1) and
``power`` (how fast the band narrows under ``full_band_at``: `scone_bt.gate.probe.NARROWING_POWER`, default 4).
``--oracle`` replays the oracle's view instead (κ̂ given each product's true mass, size and glass, as
``scone-bench gate``'s ``methods.oracle``), with the same probe readings.

    PYTHONPATH=$PWD python tools/probe_band_sweep.py --datasets tools/data/sc_probe \\
        --configs '[{"below": 1.0, "above": 0.45, "full_band_at": 0.0}, {"below": 1.0, "above": 0.45}]'
"""

from __future__ import annotations

import argparse
import json
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from scone_bt.gate.probe import ProbeOptions


def configuration(cfg: dict) -> tuple[ProbeOptions | None, float | None, float]:
    """(the probe's options or None, the strict rule's allowance, the band's narrowing power) of one configuration.
    Only an explicit ``{"below": null}`` means no probe: any other keys change the defaults they name."""
    from scone_bt.gate.probe import ProbeOptions

    options = dict(cfg)
    allowance = options.pop("allowance", 1.0)
    power = float(options.pop("power", 4.0))
    probe = None if "below" in options and options["below"] is None else ProbeOptions(**options)
    return probe, allowance, power


def main() -> None:
    from scone_bt.benchmarks.gate import replay_args, stream_results
    from scone_bt.benchmarks.replay_rates import pooled_rates
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.gate import probe as band

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", default="tools/data/sc_probe")
    ap.add_argument("--configs", required=True, help="a JSON list of configurations (module docstring)")
    ap.add_argument("--alphas", default="0.05,0.1,0.15,0.2")
    ap.add_argument(
        "--oracle", action="store_true", help="κ̂ given the true mass, size and glass (module docstring)"
    )
    a = ap.parse_args()
    args = replay_args(a.datasets)
    streams = load_streams(args, oracle=a.oracle)
    for cfg in json.loads(a.configs):
        for alpha in (float(x) for x in a.alphas.split(",")):
            t0 = time.time()
            probe, allowance, power = configuration(cfg)
            band.NARROWING_POWER = power  # band_below reads it at each call
            args.excess_allowance = allowance
            r = pooled_rates(stream_results(streams, "physical", "budget", alpha, args, probe=probe))
            line = {
                "config": cfg,
                **({"oracle": True} if a.oracle else {}),
                "alpha": alpha,
                "attempt_failure_rate": r["attempt_failure_rate"],
                "help_rate": r["help_rate"],
                "aborted_rate": r["aborted_rate"],
                "probe_s_mean": r["probe_s_mean"],
                "max_excess_failures": r["max_excess_failures"],
                "max_excess_failures_where_confident_held": r["max_excess_failures_where_confident_held"],
                "streams_where_confident_held": r["streams_where_confident_held"],
                "by_feel_attempts": r["by_feel_attempts"],
                "by_feel_failures": r["by_feel_failures"],
                "probe_failures_before_feeling": r["probe_failures_before_feeling"],
                "wall_s": round(time.time() - t0, 1),
            }
            print(json.dumps(line), flush=True)


if __name__ == "__main__":
    main()
