"""Typed blackboard keys: a key carries its type; a wrong value is refused where it is written, and reading a key
nobody wrote is an error unless the reader gives a default."""

from __future__ import annotations

import py_trees
import pytest

from scone_bt.behaviours.base import BlackboardError, Keys, StageBehaviour


class _Writer(StageBehaviour):
    WRITES = (Keys.DECISION, Keys.TARGET)

    def update(self) -> py_trees.common.Status:
        return py_trees.common.Status.SUCCESS


class _Reader(_Writer):
    READS = (Keys.DECISION, Keys.TARGET)
    WRITES = ()


def test_a_wrong_type_is_refused_where_it_is_written() -> None:
    with pytest.raises(
        BlackboardError, match=r"^w wrote str to blackboard key /gate/decision, which holds Decision$"
    ):
        _Writer("w").write(Keys.DECISION, "act")
    with pytest.raises(BlackboardError, match="which holds Decision$"):
        _Writer("w").write(Keys.DECISION, None)  # a decision is never None


def test_an_optional_key_takes_none() -> None:
    _Writer("w").write(Keys.TARGET, None)
    assert _Reader("r").read(Keys.TARGET) is None


def test_reading_an_unwritten_key_is_an_error_unless_a_default_is_given() -> None:
    reader = _Reader("r")
    with pytest.raises(
        BlackboardError, match="r read blackboard key /gate/decision before anything wrote it"
    ):
        reader.read(Keys.DECISION)
    assert reader.read(Keys.DECISION, None) is None


def test_the_error_names_the_node_that_must_tick_first() -> None:
    """A miswired tree file (PickAndPlace alone) said only that the key was unwritten."""
    import scone_bt.behaviours  # noqa: F401 (every behaviour class registered)

    with pytest.raises(BlackboardError, match=r"a node that writes it \(ConfidenceGate\) must tick before r"):
        _Reader("r").read(Keys.DECISION)


def test_keys_are_their_paths() -> None:
    assert Keys.DECISION == "/gate/decision" and Keys.DECISION.optional is False and Keys.TARGET.optional
