"""The reference implementation: R's ``ordinal::clmm`` (Christensen), run through ``Rscript`` on a data frame.

Used by the test suite to cross-check our ordered-logit fits against an established maximum-likelihood
implementation (R and the ``ordinal`` package: Debian ``r-base-core`` and ``r-cran-ordinal``). The R script ships
in the package (``scone_bt/study/r/clmm_fit.R``). Nothing here is needed to run an analysis.
"""

from __future__ import annotations

import csv
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import SconeError

__all__ = ["ClmmFit", "R_SCRIPT", "r_unavailable", "fit_clmm", "r_dataset"]

R_SCRIPT = Path(__file__).with_name("r") / "clmm_fit.R"
_MISSING_PACKAGE = 3  # clmm_fit.R's exit status when 'ordinal' is not installed


@dataclass(frozen=True)
class ClmmFit:
    """clmm's estimates (logit scale).

    Attributes:
        fixed: Coefficient name as R names it ("tempwarm", "conditionon") → (estimate, standard error).
        thresholds: Cut-point name ("1|2") → (estimate, standard error).
        random_sd: Grouping factor → estimated sd of its random intercept.
    """

    fixed: dict[str, tuple[float, float]]
    thresholds: dict[str, tuple[float, float]]
    random_sd: dict[str, float]


def r_unavailable() -> str | None:
    """Why clmm cannot run here (None when Rscript and the ordinal package are installed)."""
    rscript = shutil.which("Rscript")
    if rscript is None:
        return "Rscript not found (Debian: apt-get install r-base-core r-cran-ordinal)"
    probe = subprocess.run(
        [rscript, "-e", "quit(status = if (requireNamespace('ordinal', quietly = TRUE)) 0 else 3)"],
        capture_output=True,
        timeout=120,
    )
    if probe.returncode != 0:
        return "R package 'ordinal' not installed (Debian: apt-get install r-cran-ordinal)"
    return None


def _run(args: list[str]) -> subprocess.CompletedProcess[str]:
    rscript = shutil.which("Rscript")
    if rscript is None:
        raise SconeError("Rscript not found (Debian: apt-get install r-base-core r-cran-ordinal)")
    return subprocess.run([rscript, *args], capture_output=True, text=True, timeout=600)


def fit_clmm(frame: Any, formula: str, n_agq: int = 10) -> ClmmFit:
    """Fit ``formula`` (e.g. ``"rating ~ temp + contact + (1|judge)"``) to a pandas DataFrame with clmm.

    The response column holds integer categories; every other column of the formula is treated as a factor.
    Adaptive Gauss-Hermite quadrature with ``n_agq`` points is used when there is one random-effect term
    (the Laplace approximation otherwise).
    """
    with tempfile.TemporaryDirectory(prefix="scone-clmm-") as folder:
        data, out = Path(folder) / "data.csv", Path(folder) / "fit.csv"
        frame.to_csv(data, index=False)
        done = _run([str(R_SCRIPT), str(data), formula, str(out), str(n_agq)])
        if done.returncode == _MISSING_PACKAGE:
            raise SconeError("R package 'ordinal' not installed (Debian: apt-get install r-cran-ordinal)")
        if done.returncode != 0 or not out.is_file():
            last = (done.stderr.strip().splitlines() or ["no output"])[-1]
            raise SconeError(f"clmm failed on {formula!r}: {last}")
        fixed, thresholds, random_sd = {}, {}, {}
        with out.open(newline="") as fh:
            for row in csv.DictReader(fh):
                value = float(row["estimate"])
                se = float(row["se"]) if row["se"] not in ("", "NA") else float("nan")
                if row["kind"] == "fixed":
                    fixed[row["name"]] = (value, se)
                elif row["kind"] == "threshold":
                    thresholds[row["name"]] = (value, se)
                else:
                    random_sd[row["name"]] = value
    return ClmmFit(fixed, thresholds, random_sd)


def r_dataset(package: str, name: str) -> Any:
    """A data set shipped with an installed R package (e.g. ``ordinal``'s ``wine``) as a pandas DataFrame."""
    import pandas as pd

    with tempfile.TemporaryDirectory(prefix="scone-rdata-") as folder:
        out = Path(folder) / f"{name}.csv"
        code = (
            f"data({name}, package = '{package}'); d <- {name}; "
            "for (v in names(d)) if (is.factor(d[[v]])) d[[v]] <- as.character(d[[v]]); "
            f"write.csv(d, '{out.as_posix()}', row.names = FALSE)"
        )
        done = _run(["-e", code])
        if done.returncode != 0 or not out.is_file():
            last = (done.stderr.strip().splitlines() or ["no output"])[-1]
            raise SconeError(f"cannot read data set {name!r} of R package {package!r}: {last}")
        return pd.read_csv(out)
