"""Two rerun recordings compared entity by entity: which entities, how many rows, the same values (JSON).

    .venv/bin/python tools/compare_recordings.py before.rrd after.rrd [--ignore-tick]

Proves that a change to the recorder (`scone_bt/viz/`) records the same thing. Row ids and wall-clock timelines
are left out; with --ignore-tick the `tick` timeline is too, since a PyBullet episode ticks the tree a varying
number of times while the planner thinks (time stands still, so every other value repeats exactly). Exits 1 when
the recordings differ.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections import defaultdict

_LEFT_OUT = ("log_time", "log_tick", "rerun.controls.RowId")


def digest(path: str, ignore_tick: bool) -> dict[str, dict[str, object]]:
    """Entity path → rows, component names and a digest of its rows' values (order-independent)."""
    import rerun as rr

    reader = rr.chunk.RrdReader(path)
    rows: dict[str, int] = defaultdict(int)
    components: dict[str, set[str]] = defaultdict(set)
    values: dict[str, list[str]] = defaultdict(list)
    for chunk in reader.stream(store=reader.recordings()[0]):
        if chunk.entity_path.startswith("/__"):  # rerun's own properties
            continue
        batch = chunk.to_record_batch()
        left_out = (*_LEFT_OUT, *(("tick",) if ignore_tick else ()))
        names = [n for n in batch.schema.names if n not in left_out and "RowId" not in n]
        rows[chunk.entity_path] += chunk.num_rows
        components[chunk.entity_path].update(names)
        columns = {n: batch.column(n).to_pylist() for n in names}
        for i in range(batch.num_rows):
            row = {n: columns[n][i] for n in names}
            values[chunk.entity_path].append(json.dumps(row, sort_keys=True, default=str))
    return {
        entity: {
            "rows": rows[entity],
            "components": sorted(components[entity]),
            "digest": hashlib.sha256("\n".join(sorted(values[entity])).encode()).hexdigest()[:16],
        }
        for entity in sorted(rows)
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument(
        "--ignore-tick", action="store_true", help="leave the tick timeline out of the values"
    )
    args = parser.parse_args(argv)
    a, b = digest(args.before, args.ignore_tick), digest(args.after, args.ignore_tick)
    common = sorted(set(a) & set(b))
    report = {
        "entities": [len(a), len(b)],
        "only_before": sorted(set(a) - set(b)),
        "only_after": sorted(set(b) - set(a)),
        "rows_differ": {e: [a[e]["rows"], b[e]["rows"]] for e in common if a[e]["rows"] != b[e]["rows"]},
        "components_differ": [e for e in common if a[e]["components"] != b[e]["components"]],
        "values_differ": [e for e in common if a[e]["digest"] != b[e]["digest"]],
    }
    json.dump(report, sys.stdout, indent=2)
    print()
    same = not any(report[k] for k in ("only_before", "only_after", "rows_differ", "components_differ"))
    return 0 if same and not report["values_differ"] else 1


if __name__ == "__main__":
    sys.exit(main())
