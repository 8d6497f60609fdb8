"""Fuzzing the scenario loader like the other loaders (tests/fuzz): any input is a list of cases or one line."""

from __future__ import annotations

from pathlib import Path

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from scone_bt.errors import SconeError
from scone_bt.scenario.model import EVENT_ACTIONS, EXPECTATION_KINDS, load_scenario

FUZZ = settings(
    derandomize=True,
    deadline=None,
    database=None,
    max_examples=150,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
KEYS = [
    "description", "name", "expected", "reason", "world", "robot", "human", "events", "expect", "sweep",
    "seed", "at", "when", "kind", "object", "slot", "product", "min", "max", "below", "above", "profile",
    *EVENT_ACTIONS, *EXPECTATION_KINDS,
]  # fmt: skip
SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**12), 10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(
        ["salt", "olive oil", "unicorn", "front/0/0", "front/9/9", "example:hummus", "p01_weak_gripper"]
    ),
    st.text(max_size=20),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.sampled_from(KEYS), inner, max_size=4)
    ),
    max_leaves=12,
)
DOCS = st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=6)
VALID = {"description": "d", "expect": [{"completes": True}]}


@FUZZ
@given(doc=DOCS, base=st.booleans())
def test_any_mapping_is_cases_or_one_line(tmp_path: Path, doc: dict, base: bool) -> None:
    data = {**VALID, **doc} if base else doc
    path = tmp_path / "fuzz.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    try:
        cases = load_scenario(path)
    except SconeError as exc:
        text = str(exc)
        assert text and "\n" not in text and "\r" not in text, text
        assert text.startswith(str(path)), text
    else:
        assert cases and all(c.spec.description for c in cases)


@FUZZ
@given(raw=st.binary(max_size=200))
def test_any_bytes_are_cases_or_one_line(tmp_path: Path, raw: bytes) -> None:
    path = tmp_path / "fuzz.yaml"
    path.write_bytes(raw)
    try:
        load_scenario(path)
    except SconeError as exc:
        assert "\n" not in str(exc)
