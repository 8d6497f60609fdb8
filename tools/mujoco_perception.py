"""``scone-bench perception`` on the MuJoCo kitchen (JSON on stdout), until the benchmark takes ``--robot``.

    .venv/bin/python tools/mujoco_perception.py --scenes 5 --json docs/results/mujoco_perception.json

The benchmark's own scenes, cameras, detector and scoring (scone_bt/benchmarks/perception.py), with
`world.mj_kitchen.MjKitchen` standing where it builds PyBullet's `world.Kitchen`; every argument is the
benchmark's.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    import scone_bt.world.kitchen as pybullet_kitchen
    from scone_bt.cli.bench import main
    from scone_bt.world.mj_kitchen import MjKitchen

    pybullet_kitchen.Kitchen = MjKitchen  # type: ignore[misc,assignment]  # what `from scone_bt.world import Kitchen` returns
    sys.exit(main(["perception", *sys.argv[1:]]))
