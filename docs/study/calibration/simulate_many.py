"""Write the recovery benchmark's SIMULATED data for many seeds as CSV, for maximum-likelihood fits in R.

Usage: python docs/study/calibration/simulate_many.py OUT_FOLDER FIRST_SEED END_SEED
Per seed: a 31-participant fast study with static trust, no per-session answer noise and a known +1.0 logit
condition effect (the answers of `scone-bench study-recovery`), and Eq. (4) counts with a known +1.0 log-rate effect
(`simulate_counts`). Writes ratings.csv and counts.csv with a seed column; fit_many.R fits them.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import pandas as pd

from scone_bt.study.analysis import load_study
from scone_bt.study.power import simulate_counts
from scone_bt.study.simulate import SimulationOptions, simulate_study
from scone_bt.study.trust import TrustParameters

PARTICIPANTS = 31
EFFECT = 1.0


def main(out: Path, seeds: range) -> None:
    """Simulate every seed's study and write the two CSV files."""
    trust = TrustParameters(
        success_gain=0.0, failure_loss=0.0, help_gain=0.0, condition_effect=EFFECT, response_noise_sd=0.0
    )
    ratings, counts = [], []
    for seed in seeds:
        with tempfile.TemporaryDirectory() as folder:
            options = SimulationOptions(participants=PARTICIPANTS, fast=True, trust=trust, seed=seed)
            log = simulate_study(Path(folder) / "study.db", options, printer=lambda _line: None)
            data = load_study(log)
            log.close()
        columns = ["questionnaire", "category", "condition", "session_index", "participant", "item"]
        ratings.append(data.ratings[columns].assign(seed=seed))
        sessions = simulate_counts(PARTICIPANTS, EFFECT, seed).sessions
        counts.append(
            sessions[["participant", "condition", "session_index", "interventions"]].assign(seed=seed)
        )
    out.mkdir(parents=True, exist_ok=True)
    pd.concat(ratings).to_csv(out / "ratings.csv", index=False)
    pd.concat(counts).to_csv(out / "counts.csv", index=False)


if __name__ == "__main__":
    main(Path(sys.argv[1]), range(int(sys.argv[2]), int(sys.argv[3])))
