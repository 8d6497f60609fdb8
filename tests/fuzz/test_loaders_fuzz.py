"""Property-based fuzzing of every loader: random bytes, truncated and bit-flipped files, wrong types, huge values,
unicode. Each input gives a valid result or a one-line SconeError naming the file, and the file is never changed.

Seeded (derandomize) and bounded (max_examples per loader); the cases found while writing these are kept as
explicit regression examples (@example) below.
"""

from __future__ import annotations

import hashlib
import json
import math
import sqlite3
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from scone_bt.errors import SconeError

REPO = Path(__file__).resolve().parents[2]
FUZZ = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.function_scoped_fixture,
        HealthCheck.data_too_large,
    ],
)


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _check(counts: dict[str, int], loader: str, path: Path, load) -> Any:  # noqa: ANN001
    """A valid result or a one-line SconeError; the input file unchanged and nothing written beside it."""
    counts[loader] = counts.get(loader, 0) + 1
    before = _digest(path)
    beside = sorted(p.name for p in path.parent.iterdir())
    try:
        result = load(path)
    except SconeError as exc:
        text = str(exc)
        assert text and "\n" not in text and "\r" not in text, f"{loader}: not one line: {text!r}"
        result = exc
    assert _digest(path) == before, f"{loader} changed its input"
    assert sorted(p.name for p in path.parent.iterdir()) == beside, f"{loader} wrote beside its input"
    return result


# ---------------------------------------------------------------------------------------------- strategies
SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=40),
    st.sampled_from(["soon", "high", "maybe", "", "ïñ†érñåtîøñål 🍝", "\u202e", "1e309", "-0", "NaN"]),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=12), inner, max_size=5)
    ),
    max_leaves=12,
)


def _leaves(doc: Any, prefix: tuple = ()) -> list[tuple]:
    if isinstance(doc, dict):
        return [prefix] + [p for k, v in doc.items() for p in _leaves(v, (*prefix, k))]
    if isinstance(doc, list):
        return [prefix] + [p for i, v in enumerate(doc) for p in _leaves(v, (*prefix, i))]
    return [prefix]


def _replace(doc: Any, path: tuple, value: Any) -> Any:
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(doc, dict):
        return {k: (_replace(v, rest, value) if k == head else v) for k, v in doc.items()}
    return [(_replace(v, rest, value) if i == head else v) for i, v in enumerate(doc)]


def _delete(doc: Any, path: tuple) -> Any:
    if len(path) == 1:
        if isinstance(doc, dict):
            return {k: v for k, v in doc.items() if k != path[0]}
        return [v for i, v in enumerate(doc) if i != path[0]]
    head = path[0]
    if isinstance(doc, dict):
        return {k: (_delete(v, path[1:]) if k == head else v) for k, v in doc.items()}
    return [(_delete(v, path[1:]) if i == head else v) for i, v in enumerate(doc)]


@st.composite
def mutated_documents(draw, base: Any) -> Any:
    """The valid document `base` with one to three edits: a value replaced, a key deleted or an unknown key added."""
    doc = base
    for _ in range(draw(st.integers(1, 3))):
        paths = _leaves(doc)
        path = draw(st.sampled_from(paths))
        action = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        if action == "delete" and path:
            doc = _delete(doc, path)
        elif action == "add":
            target = draw(st.sampled_from([p for p in paths if isinstance(_get(doc, p), dict)] or [()]))
            sub = _get(doc, target)
            if isinstance(sub, dict):
                doc = _replace(doc, target, {**sub, draw(st.text(min_size=1, max_size=10)): draw(SCALARS)})
        else:
            doc = _replace(doc, path, draw(VALUES))
    return doc


def _get(doc: Any, path: tuple) -> Any:
    for p in path:
        doc = doc[p]
    return doc


@st.composite
def damaged_bytes(draw, base: bytes) -> bytes:
    """`base` truncated, bit-flipped, re-encoded or replaced by random bytes."""
    kind = draw(st.sampled_from(["truncate", "flip", "utf16", "latin1", "random", "bom", "nul"]))
    if kind == "truncate":
        return base[: draw(st.integers(0, max(0, len(base) - 1)))]
    if kind == "flip":
        data = bytearray(base)
        for _ in range(draw(st.integers(1, 8))):
            i = draw(st.integers(0, len(data) - 1))
            data[i] ^= 1 << draw(st.integers(0, 7))
        return bytes(data)
    if kind == "utf16":
        return base.decode("utf-8", "replace").encode(
            draw(st.sampled_from(["utf-16", "utf-16-le", "utf-32"]))
        )
    if kind == "latin1":
        return base.decode("utf-8", "replace").replace("a", "ä").encode("latin-1", "replace")
    if kind == "bom":
        return b"\xef\xbb\xbf" + base
    if kind == "nul":
        i = draw(st.integers(0, len(base)))
        return base[:i] + b"\x00" + base[i:]
    return draw(st.binary(max_size=4096))


def _yaml_bytes(doc: Any) -> bytes:
    try:
        return yaml.safe_dump(doc, allow_unicode=True, sort_keys=False).encode("utf-8")
    except (yaml.YAMLError, ValueError, UnicodeEncodeError):
        return b"{}"


# ---------------------------------------------------------------------------------------------- robot files
PANDA = REPO / "robots" / "panda.yaml"
PANDA_DOC = yaml.safe_load(PANDA.read_text())


def _load_robot(path: Path):  # noqa: ANN202
    from scone_bt.config import load_robot

    return load_robot(path)


def _robot_result_is_sane(result: Any) -> None:
    if isinstance(result, SconeError):
        return
    assert result.gripper.max_force > 0 and result.gripper.finger_friction >= 0
    assert result.control.rate_hz > 0 and math.isfinite(result.planner.time_limit_s)
    assert len(result.home) == result.dof


@settings(FUZZ, max_examples=150)
@given(doc=mutated_documents(PANDA_DOC))
@example(doc={**PANDA_DOC, "planner": {**PANDA_DOC["planner"], "name": "NoSuchPlanner"}})
@example(doc={**PANDA_DOC, "control": {**PANDA_DOC["control"], "rate_hz": 0}})
@example(doc={**PANDA_DOC, "gripper": {**PANDA_DOC["gripper"], "max_force": -5.0}})
@example(doc={**PANDA_DOC, "gripper": {**PANDA_DOC["gripper"], "finger_friction": -1.0}})
@example(doc={**PANDA_DOC, "control": {**PANDA_DOC["control"], "rate_hz": True}})
@example(doc={**PANDA_DOC, "home": PANDA_DOC["home"][:-1]})
def test_robot_file_mutations(tmp_path_factory, fuzz_counts, doc):
    path = tmp_path_factory.mktemp("robot") / "arm.yaml"
    path.write_bytes(_yaml_bytes(doc))
    (path.parent / "panda.urdf").write_text("<robot/>")  # relative URDF paths resolve to a file that exists
    _robot_result_is_sane(_check(fuzz_counts, "robot file", path, _load_robot))


@settings(FUZZ, max_examples=80)
@given(data=damaged_bytes(PANDA.read_bytes()))
@example(data=PANDA.read_text().encode("utf-16"))
@example(data=b"")
@example(data=b"- a\n- b\n")
@example(data=b"a: 2020-13-45\n")
def test_robot_file_bytes(tmp_path_factory, fuzz_counts, data):
    path = tmp_path_factory.mktemp("robot") / "arm.yaml"
    path.write_bytes(data)
    _robot_result_is_sane(_check(fuzz_counts, "robot file", path, _load_robot))


# ---------------------------------------------------------------------------------------------- recipes
RECIPE = {
    "id": "fuzz:pasta",
    "title": "Fuzz pasta",
    "ingredients": ["200 g pasta", "1 tsp salt"],
    "steps": ["Boil water with salt.", "Cook the pasta."],
    "step_ingredients": [["salt"], ["pasta"]],
}


def _load_recipe(path: Path):  # noqa: ANN202
    from scone_bt.recipes import load_recipe

    return load_recipe(str(path))


def _recipe_is_sane(result: Any) -> None:
    if isinstance(result, SconeError):
        return
    assert result.steps and all(isinstance(s, str) and s.strip() for s in result.steps)
    assert all(isinstance(i, str) for i in result.ingredients)
    if result.step_ingredients is not None:
        assert len(result.step_ingredients) == len(result.steps)


@settings(FUZZ, max_examples=150)
@given(doc=mutated_documents(RECIPE), suffix=st.sampled_from([".json", ".yaml"]))
@example(doc={**RECIPE, "step_ingredients": [5, 6]}, suffix=".json")
@example(doc={**RECIPE, "steps": [5]}, suffix=".yaml")
@example(doc={**RECIPE, "title": None, "id": None}, suffix=".json")
def test_recipe_mutations(tmp_path_factory, fuzz_counts, doc, suffix):
    path = tmp_path_factory.mktemp("recipe") / f"r{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps(doc, allow_nan=True), encoding="utf-8")
    else:
        path.write_bytes(_yaml_bytes(doc))
    _recipe_is_sane(_check(fuzz_counts, "recipe file", path, _load_recipe))


@settings(FUZZ, max_examples=80)
@given(
    data=damaged_bytes(json.dumps(RECIPE, ensure_ascii=False).encode()),
    suffix=st.sampled_from([".json", ".yaml"]),
)
@example(data=json.dumps(RECIPE).encode("utf-16"), suffix=".json")
@example(data=bytes(range(256)), suffix=".json")
@example(data=b"[" * 50_000, suffix=".json")
@example(data=b"a: &a [*a]\n", suffix=".yaml")
def test_recipe_bytes(tmp_path_factory, fuzz_counts, data, suffix):
    path = tmp_path_factory.mktemp("recipe") / f"r{suffix}"
    path.write_bytes(data)
    _recipe_is_sane(_check(fuzz_counts, "recipe file", path, _load_recipe))


# ---------------------------------------------------------------------------------------------- tree files
TREE = REPO / "trees" / "assistive_cooking.yaml"
TREE_DOC = yaml.safe_load(TREE.read_text())


def _load_tree(path: Path):  # noqa: ANN202
    from scone_bt.tree import load_tree_spec

    return load_tree_spec(path)


@settings(FUZZ, max_examples=150)
@given(doc=mutated_documents(TREE_DOC))
@example(doc={**TREE_DOC, "parameters": {**TREE_DOC["parameters"], "confidence_threshold": "high"}})
@example(doc={**TREE_DOC, "root": {"behaviour": "WaitForHuman", "args": {"seconds": "soon"}}})
@example(doc={**TREE_DOC, "root": {"behaviour": "DecisionIs", "args": {"kind": "maybe"}}})
@example(doc={**TREE_DOC, "root": {"behaviour": "WaitForHuman", "args": ["soon"]}})
def test_tree_mutations(tmp_path_factory, fuzz_counts, doc):
    path = tmp_path_factory.mktemp("tree") / "t.yaml"
    path.write_bytes(_yaml_bytes(doc))
    result = _check(fuzz_counts, "tree file", path, _load_tree)
    if not isinstance(result, SconeError):  # a tree that loads also builds: its args fit the constructors
        from scone_bt.tree.build import _check_args

        def walk(node: dict) -> None:
            if "behaviour" in node:
                _check_args(node["behaviour"], node.get("args") or {}, "fuzz")
            for child in node.get("children", []):
                walk(child)

        walk(result.root)


@settings(FUZZ, max_examples=60)
@given(data=damaged_bytes(TREE.read_bytes()))
def test_tree_bytes(tmp_path_factory, fuzz_counts, data):
    path = tmp_path_factory.mktemp("tree") / "t.yaml"
    path.write_bytes(data)
    _check(fuzz_counts, "tree file", path, _load_tree)


# ---------------------------------------------------------------------------------------------- profiles
PROFILE = REPO / "tools" / "profiles" / "p01_weak_gripper.yaml"
PROFILE_DOC = {
    **yaml.safe_load(PROFILE.read_text()),
    "camera": {"noise_std": 2.0},
    "injected": [{"stage": "grasp", "rate": 0.5, "materials": ["glass"]}],
    "calibration_offset": [0.01, 0.0, 0.0],
}


def _load_profile(path: Path):  # noqa: ANN202
    from scone_bt.benchmarks.self_confidence.profiles import load_profile

    return load_profile(path)


@settings(FUZZ, max_examples=120)
@given(doc=mutated_documents(PROFILE_DOC))
@example(doc={**PROFILE_DOC, "seed": True})
@example(doc={**PROFILE_DOC, "gripper": {"finger_friction": float("nan")}})
def test_profile_mutations(tmp_path_factory, fuzz_counts, doc):
    path = tmp_path_factory.mktemp("profile") / "p.yaml"
    path.write_bytes(_yaml_bytes(doc))
    result = _check(fuzz_counts, "profile file", path, _load_profile)
    if not isinstance(result, SconeError):
        assert all(math.isfinite(v) for v in result.calibration_offset)
        assert all(0 <= i.rate <= 1 for i in result.injected)


@settings(FUZZ, max_examples=40)
@given(data=damaged_bytes(PROFILE.read_bytes()))
def test_profile_bytes(tmp_path_factory, fuzz_counts, data):
    path = tmp_path_factory.mktemp("profile") / "p.yaml"
    path.write_bytes(data)
    _check(fuzz_counts, "profile file", path, _load_profile)


# ---------------------------------------------------------------------------------------------- kitchen files
KITCHEN = REPO / "perception" / "kitchen.yaml"


def _load_kitchen(path: Path):  # noqa: ANN202
    from scone_bt.config import load_kitchen

    return load_kitchen(path)


@settings(FUZZ, max_examples=40)
@given(data=damaged_bytes(KITCHEN.read_bytes()))
def test_kitchen_bytes(tmp_path_factory, fuzz_counts, data):
    path = tmp_path_factory.mktemp("kitchen") / "kitchen.yaml"
    path.write_bytes(data)
    _check(fuzz_counts, "kitchen file", path, _load_kitchen)


# ---------------------------------------------------------------------------------------------- stores
def _valid_study_log(folder: Path) -> bytes:
    from scone_bt.study import StudyLog, plan_session

    path = folder / "seed-study.db"
    with StudyLog(path) as log:
        sid = log.start_session(plan_session("P01", "A", 1))
        for i in range(30):
            log.record_event(sid, "outcome", {"i": i, "object": "salt"})
    return path.read_bytes()


def _valid_experience(folder: Path) -> bytes:
    from scone_bt.experience import ExperienceStore
    from scone_bt.experience.types import Outcome

    path = folder / "seed-exp.db"
    with ExperienceStore(path) as store:
        for i in range(30):
            store.append(
                Outcome(float(i), "Put salt on table", "salt", "minilm", i % 2 == 0, context={"i": i})
            )
    return path.read_bytes()


@pytest.fixture(scope="module")
def store_bytes(tmp_path_factory) -> dict[str, bytes]:
    folder = tmp_path_factory.mktemp("stores")
    return {"study": _valid_study_log(folder), "experience": _valid_experience(folder)}


def _read_study_log(path: Path):  # noqa: ANN202
    from scone_bt.study import StudyLog

    with StudyLog(path, readonly=True) as log:
        return len(log.sessions()), len(log.events()), len(log.responses())


@settings(FUZZ, max_examples=60)
@given(data=st.data())
def test_study_log_damage_read_only(tmp_path_factory, fuzz_counts, store_bytes, data):
    raw = store_bytes["study"]
    damaged = data.draw(damaged_bytes(raw) if data.draw(st.booleans()) else _page_damage(raw))
    path = tmp_path_factory.mktemp("study") / "study.db"
    path.write_bytes(damaged)
    _check(fuzz_counts, "study log", path, _read_study_log)


def _open_experience(path: Path):  # noqa: ANN202
    from scone_bt.experience import ExperienceStore

    with ExperienceStore(path) as store:
        read = len(store.outcomes())
        return read, len(store.quarantined)  # rows that read back, rows quarantined (named in a warning)


@settings(FUZZ, max_examples=60)
@given(data=st.data())
def test_experience_store_damage(tmp_path_factory, fuzz_counts, store_bytes, data):
    raw = store_bytes["experience"]
    damaged = data.draw(damaged_bytes(raw) if data.draw(st.booleans()) else _page_damage(raw))
    path = tmp_path_factory.mktemp("exp") / "exp.db"
    path.write_bytes(damaged)
    result = _check(fuzz_counts, "experience store", path, _open_experience)
    if not isinstance(result, SconeError):  # accepted: ours and sound; every row reads back or is quarantined
        read, quarantined = result
        with sqlite3.connect(f"file:{path}?mode=ro&immutable=1", uri=True) as db:
            assert db.execute("PRAGMA quick_check").fetchone()[0] == "ok"
            assert db.execute("SELECT COUNT(*) FROM outcomes").fetchone()[0] == read + quarantined


def _page_damage(raw: bytes):  # -> strategy
    """One SQLite page (4 kB) partly overwritten: the "one corrupt page" case."""

    @st.composite
    def build(draw):  # noqa: ANN001, ANN202
        pages = max(1, len(raw) // 4096)
        page = draw(st.integers(0, pages - 1))
        offset = page * 4096 + draw(st.integers(0, 4000))
        junk = draw(st.binary(min_size=1, max_size=96))
        return raw[:offset] + junk + raw[offset + len(junk) :]

    return build()


# ---------------------------------------------------------------------------------------------- CSV files
@settings(FUZZ, max_examples=60)
@given(data=st.data())
def test_dataset_csv(tmp_path_factory, fuzz_counts, data):
    from scone_bt.benchmarks.self_confidence.dataset import read_dataset

    good = "action,object,outcome,failure_stage,seed\nPut salt on table,salt,success,,1\nPut oil on table,oil,failure,grasp,2\n"
    raw = data.draw(damaged_bytes(good.encode()))
    path = tmp_path_factory.mktemp("csv") / "d.csv"
    path.write_bytes(raw)
    _check(fuzz_counts, "dataset CSV", path, read_dataset)


RATINGS = REPO / "tests" / "study" / "data" / "lab_ratings.csv"
SESSIONS = REPO / "tests" / "study" / "data" / "lab_sessions.csv"


@settings(FUZZ, max_examples=40)
@given(data=st.data(), which=st.sampled_from(["ratings", "sessions"]))
def test_ratings_csv(tmp_path_factory, fuzz_counts, data, which):
    from scone_bt.study.ratings_csv import load_ratings_csv

    folder = tmp_path_factory.mktemp("ratings")
    ratings, sessions = folder / "ratings.csv", folder / "sessions.csv"
    ratings.write_bytes(RATINGS.read_bytes())
    sessions.write_bytes(SESSIONS.read_bytes())
    target = ratings if which == "ratings" else sessions
    target.write_bytes(data.draw(damaged_bytes(target.read_bytes())))
    _check(fuzz_counts, "ratings CSV", target, lambda _p: load_ratings_csv(ratings, sessions))


KITCHEN_DOC = yaml.safe_load(KITCHEN.read_text())


@settings(FUZZ, max_examples=80)
@given(doc=mutated_documents(KITCHEN_DOC))
@example(doc={**KITCHEN_DOC, "scene": {**KITCHEN_DOC["scene"], "place_spots": [5, [0.4, -0.3]]}})
def test_kitchen_mutations(tmp_path_factory, fuzz_counts, doc):
    folder = tmp_path_factory.mktemp("kitchen")
    path = folder / "kitchen.yaml"
    path.write_bytes(_yaml_bytes(doc))
    catalogue = KITCHEN.parent / "catalogue"  # relative catalogue paths resolve as beside the real file
    if catalogue.is_dir():
        (folder / "catalogue").symlink_to(catalogue)
    _check(fuzz_counts, "kitchen file", path, _load_kitchen)
