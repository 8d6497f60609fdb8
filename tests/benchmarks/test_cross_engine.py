"""The promise across bodies: executions paired by index between two engines' datasets, the outcomes that flip,
and the decisions a budget needs before its realised failure rate is kept again."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.benchmarks.cross_engine import engine_gap, realised_rates, recovery_decisions
from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord, write_records
from scone_bt.errors import ConfigError


def _rows(outcomes: list[str | None], objects: list[str] | None = None) -> list[ExecutionRecord]:
    """Records with these outcomes: None is a success, else the failure stage."""
    names = objects or [f"p{i}" for i in range(len(outcomes))]
    return [
        ExecutionRecord(i, f"Put {n} on table", n, stage is None, stage, 1000 + i)
        for i, (n, stage) in enumerate(zip(names, outcomes, strict=True))
    ]


def test_outcomes_are_paired_by_execution_and_flips_named(tmp_path: Path) -> None:
    before, after = tmp_path / "sim", tmp_path / "mujoco"
    write_records(before / "p00.csv", _rows([None, None, "grasp", "grasp", None]))
    write_records(after / "p00.csv", _rows([None, "transit", None, "place", None]))
    gap = engine_gap(before, after, ["p00"])["p00"]
    assert gap.matched == 5
    assert (gap.success_rate_prior, gap.success_rate) == (0.6, 0.6)
    assert (gap.to_failure, gap.to_success, gap.stage_changes) == (1, 1, 1)
    assert [(f.index, f.object, f.before, f.after) for f in gap.flips] == [
        (1, "p1", "success", "transit"),
        (2, "p2", "grasp", "success"),
    ]


def test_only_executions_in_both_folders_are_compared(tmp_path: Path) -> None:
    write_records(tmp_path / "a" / "p00.csv", _rows([None, "grasp", None]))
    write_records(tmp_path / "b" / "p00.csv", _rows([None, None]))
    gap = engine_gap(tmp_path / "a", tmp_path / "b", ["p00"])["p00"]
    assert gap.matched == 2 and gap.to_success == 1 and gap.success_rate_prior == 0.5


def test_another_task_at_the_same_index_is_a_one_line_error(tmp_path: Path) -> None:
    write_records(tmp_path / "a" / "p00.csv", _rows([None, None], ["salt", "sugar"]))
    write_records(tmp_path / "b" / "p00.csv", _rows([None, None], ["salt", "flour"]))
    with pytest.raises(ConfigError, match="execution 1 is 'flour'.*has 'sugar'"):
        engine_gap(tmp_path / "a", tmp_path / "b", ["p00"])
    with pytest.raises(ConfigError, match="p01.csv: no such dataset"):
        engine_gap(tmp_path / "a", tmp_path / "b", ["p01"])


def test_realised_rate_counts_attempts_since_the_move() -> None:
    assert realised_rates([-1, 1, 0, -1, 1, 1]) == [None, 0.0, 0.5, 0.5, 1 / 3, 0.25]


@pytest.mark.parametrize(
    ("trace", "alpha", "expected"),
    [
        ([1, 1, 1, -1, 1], 0.10, 0),  # never above α + 0.02
        ([-1, -1], 0.10, 0),  # no attempt: nothing to keep
        (
            [0, 1, 1, 1, 1, 1, 1, 1, 1],
            0.10,
            8,
        ),  # 1/8 = 0.125 > 0.12, 1/9 = 0.111 ≤ 0.12: back after 8 decisions
        ([1, 1, 0, 1, 1, 1, 1, 0], 0.20, None),  # ends at 2/8 = 0.25 > 0.22
        (
            [0, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1],
            0.15,
            11,
        ),  # a second failure: above until 2/11, 2/12 ≤ 0.17
    ],
)
def test_recovery_is_the_decisions_before_the_rate_stays_within_the_band(
    trace: list[int], alpha: float, expected: int | None
) -> None:
    assert recovery_decisions(trace, alpha) == expected
