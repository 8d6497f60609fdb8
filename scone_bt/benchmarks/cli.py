"""``scone-bench core`` and ``scone-bench viz``: the SCONE core's latency and rerun's logging overhead.

Registration is cheap; each handler imports its benchmark module (which pulls in rerun, PyBullet or the embedders).
"""

from __future__ import annotations

import argparse

from scone_bt.argparsing import path_arg

__all__ = ["register"]


def _core(args: argparse.Namespace) -> int:
    from scone_bt.benchmarks.core import run

    return run(args)


def _viz(args: argparse.Namespace) -> int:
    from scone_bt.benchmarks.viz import main
    from scone_bt.checks import check_output_file, check_positive_int, check_range

    check_positive_int(args.ticks, "--ticks", maximum=100_000)
    check_positive_int(args.frame_every, "--frame-every", maximum=100_000)
    check_range(args.tick_seconds, "--tick-seconds", 0.001, 10.0)
    if args.save_demo is not None:  # before the episodes run: the file a user names is not lost to the demo
        inputs = {"--json": [args.json]} if args.json is not None else {}
        check_output_file(args.save_demo, "--save-demo", kind="rrd", inputs=inputs, force=args.force)
    return main(args)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``core`` and ``viz`` to ``scone-bench``."""
    c = sub.add_parser("core", help="embedding throughput, κ̂ latency and the decision path (JSON)")
    c.add_argument("--quick", action="store_true", help="fewer repetitions")
    c.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    c.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    c.set_defaults(func=_core)
    v = sub.add_parser("viz", help="rerun logging overhead on a headless episode tick (JSON)")
    v.add_argument("--ticks", type=int, default=120, help="control ticks per run (default: 120)")
    v.add_argument(
        "--tick-seconds", type=float, default=0.1, help="simulated seconds per tick (default: 0.1)"
    )
    v.add_argument("--frame-every", type=int, default=10, help="camera frame every N ticks (default: 10)")
    v.add_argument("--robot-geometry", default="visual", choices=["visual", "collision"], help="robot meshes")
    v.add_argument("--seed", type=int, default=0)
    v.add_argument(
        "--headless-runs",
        type=int,
        default=3,
        help="scone-run processes without and with --save, each (default: 3; 0 skips the headless run)",
    )
    v.add_argument("--save-demo", type=path_arg, help="keep the recording here (else a temporary file)")
    v.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    v.add_argument(
        "--force",
        action="store_true",
        help="let --save-demo or --json replace an existing file of another kind",
    )
    v.set_defaults(func=_viz)
