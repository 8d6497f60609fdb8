"""Fig. 3 as published: per measure, the posterior contrasts of policy (self-confidence on - off) and of G
(session order in the paper model, group B - A in the extended one) as histograms with the 95 % HDI bar, the ROPE
lines and text labels, and candle plots (mean ± sd, min-max whiskers) of the scores by policy and by G."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from scone_bt.study.analysis import AnalysisResult, StudyData

__all__ = ["plot_results"]

_TITLES = {
    "mdmt": "MDMT performance",
    "tps_hri": "TPS-HRI",
    "trust": "trust (all questionnaires)",
    "interventions": "interventions",
}
_SCORE_COLUMN = {"trust": "mdmt"}
_POLICY_COLOURS = ("#c4553d", "#3d8c5a")  # off red, on green
_G_COLOURS = ("#6c7a89", "#3b5b92")  # neutral: G is no treatment


def _padded(values: Any, *more: float, pad: float = 0.08) -> tuple[float, float]:
    """Axis limits that hold every value with a margin of ``pad`` of their span on each side, so that no line
    (ROPE, zero, HDI end) is drawn on the axis frame."""
    import numpy as np

    v = np.concatenate([np.asarray(values, dtype=float).ravel(), np.asarray(more, dtype=float)])
    v = v[np.isfinite(v)]
    lo, hi = float(v.min()), float(v.max())
    margin = pad * (hi - lo) if hi > lo else 0.5
    return lo - margin, hi + margin


def _histogram(
    ax: Any, samples: Any, contrast: Any, rope: tuple[float, float], hdi_prob: float, scale: str
) -> None:
    ax.hist(samples, bins=40, color="#9bbcd4", edgecolor="white")
    ymax = ax.get_ylim()[1]
    for x in rope:
        ax.axvline(x, color="#d08a1e", lw=1.2, ls="--")
    ax.text(rope[1], ymax * 0.95, " ROPE", color="#d08a1e", fontsize=7, va="top")
    lo, hi = contrast.hdi
    y = ymax * 0.12  # the bar's end labels below it stay above the axis frame
    ax.plot([lo, hi], [y, y], color="black", lw=4, solid_capstyle="butt")
    ax.text((lo + hi) / 2, y + ymax * 0.04, f"{hdi_prob:.0%} HDI", ha="center", fontsize=7)
    ax.text(lo, y - ymax * 0.02, f"{lo:.2f}", ha="center", va="top", fontsize=7)
    ax.text(hi, y - ymax * 0.02, f"{hi:.2f}", ha="center", va="top", fontsize=7)
    ax.text(
        0.02,
        0.95,
        f"mean {contrast.mean:.2f}\nP(>0) {contrast.p_positive:.2f}\n{contrast.decision}",
        transform=ax.transAxes,
        fontsize=7,
        va="top",
    )
    ax.axvline(0.0, color="grey", lw=0.8, ls=":")
    ax.set_xlim(*_padded(samples, *rope, 0.0, lo, hi))
    ax.set_ylim(0, ymax * 1.05)
    ax.set_xlabel(f"{contrast.label} ({scale})", fontsize=8)
    ax.set_yticks([])


def _candles(
    ax: Any,
    frame: Any,
    column: str,
    by: str,
    levels: tuple[str, str],
    names: tuple[str, str],
    colours: tuple[str, str],
) -> None:
    """Mean ± sd as a box, min-max as whiskers, per level."""
    import numpy as np

    extent: list[float] = []
    for x, level in enumerate(levels):
        vals = frame[frame[by].astype(str) == level][column].to_numpy(dtype=float)
        vals = vals[~np.isnan(vals)]
        if not len(vals):
            continue
        m = vals.mean()
        s = vals.std(ddof=1) if len(vals) > 1 else 0.0
        colour = colours[x]
        extent += [vals.min(), vals.max(), m - s, m + s]
        ax.vlines(x, vals.min(), vals.max(), color=colour, lw=1)
        ax.bar(x, 2 * s, bottom=m - s, width=0.45, color=colour, alpha=0.45, edgecolor=colour)
        ax.hlines(m, x - 0.22, x + 0.22, color=colour, lw=2.5)
        ax.text(x + 0.26, m, f"{m:.2f}", fontsize=7, va="center")
    ax.set_xticks([0, 1], list(names), fontsize=8)
    ax.set_xlim(-0.6, 1.8)
    if extent:
        ax.set_ylim(*_padded(extent))  # whiskers and boxes end inside the frame


def plot_results(
    result: AnalysisResult, data: StudyData, path: str | Path, pdf: str | Path | None = None
) -> Path:
    """Write the figure as PNG (and PDF when `pdf` is given); the title says SIMULATED for simulated data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = list(result.fits)
    g = "session" if result.options.specification == "paper" else "group"
    g_column, g_levels, g_names = {
        "session": ("session_index", ("1", "2"), ("session 1", "session 2")),
        "group": ("group", ("A", "B"), ("group A", "group B")),
    }[g]
    fig, axes = plt.subplots(len(models), 4, figsize=(15, 3.0 * len(models)), squeeze=False)
    for row, model in enumerate(models):
        title = _TITLES.get(model, model)
        scale = "log-rate" if model == "interventions" else "logit"
        column = _SCORE_COLUMN.get(model, model)
        unit = (
            "count per session" if model == "interventions" else data.score_units.get(column, "mean rating")
        )
        for col, factor in enumerate(("condition", g)):
            c = result.contrast(model, factor)
            _histogram(
                axes[row][col],
                result.fits[model].samples[factor],
                c,
                result.options.rope,
                result.options.hdi_prob,
                scale,
            )
            axes[row][col].set_title(f"{title}: {'policy' if factor == 'condition' else g}", fontsize=9)
        frame = data.sessions
        if column in frame:
            _candles(
                axes[row][2], frame, column, "condition", ("off", "on"), ("SC off", "SC on"), _POLICY_COLOURS
            )
            _candles(axes[row][3], frame, column, g_column, g_levels, g_names, _G_COLOURS)
        for col in (2, 3):
            axes[row][col].set_ylabel(unit, fontsize=8)
        axes[row][2].set_title(f"{title}: scores by policy", fontsize=9)
        axes[row][3].set_title(f"{title}: scores by {g}", fontsize=9)
    label = "SIMULATED DATA — " if result.simulated else ""
    fig.suptitle(
        f"{label}posterior contrasts ({result.options.specification} model; HDI and ROPE) and scores",
        fontsize=11,
        color="#b00020" if result.simulated else "black",
    )
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=110)
    if pdf is not None:
        fig.savefig(Path(pdf))
    plt.close(fig)
    return out
