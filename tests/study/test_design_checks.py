"""The study log's route checks the crossover as the CSV route does: one group only is refused (condition and
session order confounded); a participant with one condition only is left out, said in one line."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.study import StudyLog, plan_session
from scone_bt.study.analysis import load_study


def _log(tmp_path, sessions):
    log = StudyLog(tmp_path / "study.db")
    for participant, group, index in sessions:
        sid = log.start_session(plan_session(participant, group, index))
        log.end_session(sid, {})
    return log


def test_one_group_only_is_refused_in_one_line(tmp_path):
    log = _log(tmp_path, [("P01", "A", 1), ("P01", "A", 2), ("P02", "A", 1), ("P02", "A", 2)])
    with pytest.raises(SconeError) as exc:
        load_study(log)
    message = str(exc.value)
    assert "every participant is in group A (order on/off)" in message and "confounded" in message
    assert "\n" not in message


def test_a_participant_with_one_session_is_left_out_and_said(tmp_path):
    log = _log(
        tmp_path,
        [("P01", "A", 1), ("P01", "A", 2), ("P02", "B", 1), ("P02", "B", 2), ("P03", "A", 1)],
    )
    data = load_study(log)
    assert sorted(set(data.sessions["participant"])) == ["P01", "P02"]
    (note,) = data.notes
    assert "P03 (on only)" in note and "left out" in note and "\n" not in note


def test_analyze_prints_the_warning_and_refuses_before_sampling(tmp_path, capsys):
    from scone_bt.study.cli import main

    _log(tmp_path, [("P01", "B", 1), ("P01", "B", 2)]).close()
    assert main(["analyze", "--db", str(tmp_path / "study.db"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "every participant is in group B (order off/on)" in err and len(err.strip().splitlines()) == 1


def test_fig3_keeps_every_line_off_the_axis_frame():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from scone_bt.study.analysis import Contrast
    from scone_bt.study.figure import _histogram

    samples = np.random.default_rng(0).normal(0.8, 0.15, 2000)  # the ROPE's -0.18 lies far left of the draws
    contrast = Contrast("mdmt", "condition", "condition (on - off)", "d", "paper", 0.8, 0.15, (0.5, 1.1),
                        (-0.18, 0.18), 1.0, "reject")  # fmt: skip
    fig, ax = plt.subplots()
    _histogram(ax, samples, contrast, (-0.18, 0.18), 0.95, "logit")
    lo, hi = ax.get_xlim()
    for x in (-0.18, 0.18, 0.0, samples.min(), samples.max()):
        assert lo + 0.06 * (hi - lo) < x < hi - 0.06 * (hi - lo)  # matplotlib's own margin is 5 %
    plt.close(fig)
