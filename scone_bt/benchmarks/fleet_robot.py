"""One robot process of the fleet benchmark: it replays a real attempt stream into a shared experience store.

    python -m scone_bt.benchmarks.fleet_robot STORE ROBOT_ID ARM PROFILE DATASET.csv N [INTERVAL_S]

Attempt k is row k of DATASET (a self-confidence dataset: real simulated executions with their outcomes). The
robot stores attempt k with outcome_id "<robot>:<k>" and prints "k latency_ms" only after `append` returned, so
every printed attempt is acknowledged (committed). Started again after a crash, it asks the store which attempts
it has and re-sends the last one (as a robot unsure whether its last write landed would), then continues.
"""

from __future__ import annotations

import sys
import time

__all__ = ["main"]


def main(argv: list[str]) -> int:
    from scone_bt.benchmarks.self_confidence.dataset import read_dataset
    from scone_bt.experience import Outcome, open_store

    store_spec, robot_id, arm, profile, dataset_path, n_text, *rest = argv
    n, interval = int(n_text), float(rest[0]) if rest else 0.0
    (data,) = read_dataset(dataset_path)[:1]
    store = open_store(store_spec)
    mine = sorted(int(o.outcome_id.split(":")[1]) for o in store.outcomes(robot_id=robot_id))
    start = max(0, mine[-1]) if mine else 0  # re-send the last stored attempt: the key makes it a no-op
    for k in range(start, n):
        i = k % len(data)
        outcome = Outcome(
            time=time.time(),
            action=data.actions[i],
            object_name=data.objects[i],
            embedder="minilm",
            success=bool(data.success[i]),
            failure_stage=data.failure_stages[i] or None,
            context={"attempt": k, "dataset_row": i},
            robot_id=robot_id,
            arm=arm,
            profile=profile,
            outcome_id=f"{robot_id}:{k}",
        )
        t0 = time.perf_counter()
        store.append(outcome)
        print(k, round(1000 * (time.perf_counter() - t0), 3), flush=True)
        if interval:
            time.sleep(interval)
    store.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
