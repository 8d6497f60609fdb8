"""The episode benchmark's recipes on each robot backend, side by side (JSON on stdout).

    .venv/bin/python tools/engine_episodes.py sim mujoco > docs/results/mujoco_episodes.json

The same episodes as ``scone-bench episode`` (its default recipes, seed i for the i-th, 4 distractors), run on
each backend named, one after another in one process. Per backend: simulated seconds per wall second and per CPU
second (this process's, renderer threads included), and per episode its outcome counts and start-up to first
decision. The machine's load average is printed with them: on a shared machine wall time measures other work too.
"""

from __future__ import annotations

import json
import os
import sys
import time


def measure(backend: str) -> dict[str, object]:
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.benchmarks.episode import DEFAULT_RECIPES
    from scone_bt.episode import EpisodeOptions, run_episode
    from scone_bt.quiet import c_stdout_silenced

    episodes = []
    total_sim = total_wall = total_cpu = 0.0
    for i, recipe in enumerate(DEFAULT_RECIPES):
        options = EpisodeOptions(
            backend=backend,
            recipe=recipe,
            seed=i,
            distractors=4,
            max_ticks=4000,
            behaviour=BehaviourOptions(seed=i),
        )
        cpu0 = time.process_time()
        with c_stdout_silenced():
            s = run_episode(options, printer=lambda _line: None)
        cpu = time.process_time() - cpu0
        total_sim, total_wall, total_cpu = total_sim + s.sim_time, total_wall + s.wall_time, total_cpu + cpu
        episodes.append(
            {
                "recipe": recipe,
                "completed": s.completed,
                "attempted": s.attempted,
                "successes": s.successes,
                "failures": s.failures,
                "help_requests": s.help_requests,
                "sim_s": round(s.sim_time, 1),
                "wall_s": round(s.wall_time, 2),
                "cpu_s": round(cpu, 2),
                "startup_to_first_decision_s": round(s.startup_to_first_decision_s or float("nan"), 2),
            }
        )
    return {
        "backend": backend,
        "load_average_after": [round(x, 1) for x in os.getloadavg()],
        "sim_per_wall": round(total_sim / total_wall, 2),
        "sim_per_cpu": round(total_sim / total_cpu, 2),
        "episodes": episodes,
    }


def main(backends: list[str]) -> int:
    report = {"cpus": os.cpu_count(), "results": [measure(b) for b in backends or ["sim", "mujoco"]]}
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
