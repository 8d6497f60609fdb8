"""Convert the saved results of Soh et al.'s trust-transfer models (code/results/*.pkl in
clear-nus/human-trust-transfer) into tools/data/trust/paper_results.json, so `scone-bench trust` reads JSON, never
pickles. Run once against a checkout or bare mirror of that repository:

    git clone --bare https://github.com/clear-nus/human-trust-transfer mirror.git
    python tools/trust_paper_results.py --git-dir mirror.git

Each pickle holds, per test fold, (MAE, NLL, array of [predicted, true] trust on the sigmoid(rating - 3.5) scale).
The file names follow the paper's notebook (ModelComparison.ipynb): <domain>_<model>_<latent dim>_<split>_<mode>.
"""

from __future__ import annotations

import argparse
import io
import json
import pickle
import subprocess
from pathlib import Path

# The paper's names (ModelComparison.ipynb) -> the pickle's model, latent dimension and GP mode.
MODELS = {
    "rnn": ("neural", 30, 1),
    "pogp": ("gp", 3, 2),
    "pmgp": ("gp", 3, 1),
    "gp": ("gp", 3, 0),
    "lineargaussian": ("lineargaussian", 2, 0),
    "constant": ("constant", 2, 0),
}
SPLITS = {"3participant": "participants", "LOOtask": "tasks"}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--git-dir", type=Path, required=True)
    p.add_argument(
        "--out", type=Path, default=Path(__file__).parent / "data" / "trust" / "paper_results.json"
    )
    args = p.parse_args()
    git = ["git", f"--git-dir={args.git_dir}"]
    commit = subprocess.run(
        [*git, "rev-parse", "HEAD"], check=True, capture_output=True, text=True
    ).stdout.strip()
    out: dict = {"source": "clear-nus/human-trust-transfer", "commit": commit, "results": {}}
    for domain in ("household", "driving"):
        for name, (model, dim, mode) in MODELS.items():
            for split, ours in SPLITS.items():
                path = f"code/results/{domain}_{model}_{dim}_{split}_{mode}.pkl"
                blob = subprocess.run([*git, "show", f"HEAD:{path}"], check=True, capture_output=True).stdout
                folds = pickle.load(io.BytesIO(blob))  # the paper's own results files
                out["results"].setdefault(domain, {}).setdefault(name, {})[ours] = {
                    "file": path,
                    "folds": [
                        {
                            "mae": float(mae),
                            "nll": float(nll),
                            "predicted": [round(float(v), 7) for v in res[:, 0]],
                            "target": [round(float(v), 7) for v in res[:, 1]],
                        }
                        for mae, nll, res in folds
                    ],
                }
    args.out.write_text(json.dumps(out, separators=(",", ":")) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
