"""A figure in the layout of the paper's Fig. 3: per measure, the posterior contrasts between conditions and between
groups (histograms with the 95 % HDI and the ROPE) and mean ± sd candle plots of the original scores."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from scone_bt.study.analysis import AnalysisResult, StudyData

__all__ = ["plot_results"]

_TITLES = {
    "mdmt": ("MDMT performance", "score (0-7)", "mdmt"),
    "tps_hri": ("TPS-HRI", "score (%)", "tps_hri"),
    "trust": ("trust (MDMT + TPS-HRI)", "MDMT score (0-7)", "mdmt"),
    "interventions": ("interventions", "count per session", "interventions"),
}


def plot_results(result: AnalysisResult, data: StudyData, path: str | Path) -> Path:
    """Write the figure as PNG; the title says SIMULATED for simulated data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = list(result.fits)
    fig, axes = plt.subplots(len(models), 3, figsize=(12, 3.2 * len(models)), squeeze=False)
    lo, hi = result.options.rope
    for row, model in enumerate(models):
        title, ylabel, column = _TITLES[model]
        scale = "log-rate" if model == "interventions" else "logit"
        for col, param in enumerate(("b_C", "b_G")):
            ax = axes[row][col]
            c = result.contrast(model, param)
            samples = result.fits[model].samples[param]
            ax.hist(samples, bins=40, color="#7aa6c2", edgecolor="white")
            ax.axvspan(lo, hi, color="#f0b25a", alpha=0.35, label=f"ROPE [{lo:g}, {hi:g}]")
            ymax = ax.get_ylim()[1]
            ax.plot(
                c.hdi,
                [ymax * 0.05] * 2,
                color="black",
                lw=4,
                solid_capstyle="butt",
                label=f"{result.options.hdi_prob:.0%} HDI",
            )
            ax.axvline(0.0, color="grey", lw=0.8, ls=":")
            ax.set_title(
                f"{title}: {c.name}\nmean {c.mean:.2f}, HDI [{c.hdi[0]:.2f}, {c.hdi[1]:.2f}] → {c.decision}",
                fontsize=9,
            )
            ax.set_xlabel(f"contrast ({scale})")
            ax.set_yticks([])
            if row == 0 and col == 0:
                ax.legend(fontsize=7, loc="upper left")
        ax = axes[row][2]
        frame = data.sessions.dropna(subset=[column])
        positions, labels = [], []
        for i, (cond, colour) in enumerate((("off", "#c4553d"), ("on", "#3d8c5a"))):
            for j, grp in enumerate(("A", "B")):
                vals = frame[(frame["condition"] == cond) & (frame["group"] == grp)][column].to_numpy(
                    dtype=float
                )
                x = i * 3 + j
                if len(vals):
                    m, s = vals.mean(), vals.std(ddof=1) if len(vals) > 1 else 0.0
                    ax.errorbar([x], [m], yerr=[s], fmt="o", color=colour, capsize=6, lw=2, ms=7)
                positions.append(x)
                labels.append(f"SC {cond}\ngroup {grp}")
        ax.set_xticks(positions, labels, fontsize=7)
        ax.set_xlim(-0.8, 4.8)
        ax.set_ylabel(ylabel)
        ax.set_title(f"{title}: mean ± sd", fontsize=9)
    label = "SIMULATED DATA — " if result.simulated else ""
    fig.suptitle(
        f"{label}posterior contrasts (HDI and ROPE) and original scores",
        fontsize=11,
        color="#b00020" if result.simulated else "black",
    )
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
