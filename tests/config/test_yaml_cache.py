"""Large configuration files are kept parsed on disk: read back equal to a parse, never stale, never an error."""

from pathlib import Path

import pytest
import yaml

from scone_bt.config import yaml_io
from scone_bt.config.yaml_io import _UNPARSED, _fast_parse, read_yaml
from scone_bt.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def store(tmp_path, monkeypatch):
    monkeypatch.setenv("SCONE_BT_CACHE", str(tmp_path))
    monkeypatch.delenv(yaml_io.YAML_CACHE_ENV, raising=False)
    return tmp_path / "yaml"


def _no_parser(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("parsed although a parse was kept")

    monkeypatch.setattr(yaml_io.yaml, "load", refuse)


def test_every_shipped_file_reads_back_as_it_parses(store, monkeypatch):
    files = [p for folder in ("robots", "perception", "trees") for p in (ROOT / folder).rglob("*.yaml")]
    texts = {p: p.read_text(encoding="utf-8") for p in files}
    first = {p: _fast_parse(t) for p, t in texts.items()}
    kept = [p for p, t in texts.items() if len(t) >= yaml_io.CACHED_MIN_CHARS]
    assert len(kept) >= 10 and len(list(store.glob("*.marshal"))) == len(set(texts[p] for p in kept))
    reference = {p: yaml.safe_load(texts[p]) for p in kept}
    _no_parser(monkeypatch)
    for p in kept:
        again = _fast_parse(texts[p])
        assert again == first[p] == reference[p], p
        assert again is not first[p]  # a fresh copy: a caller may change what it gets
    assert (
        read_yaml(ROOT / "perception" / "catalogue" / "bags.yaml")
        == first[ROOT / "perception/catalogue/bags.yaml"]
    )


def test_an_edited_file_is_parsed_anew(store, tmp_path, monkeypatch):
    path = tmp_path / "family.yaml"
    rows = "".join(f"  - {{name: item {i}, size: [0.1, 0.2, 0.3]}}\n" for i in range(100))
    path.write_text("family: test\nproducts:\n" + rows)
    assert read_yaml(path)["products"][0]["name"] == "item 0"
    path.write_text("family: test\nproducts:\n" + rows.replace("item 0", "item zero"))
    assert read_yaml(path)["products"][0]["name"] == "item zero"
    assert len(list(store.glob("*.marshal"))) == 2


def test_a_damaged_or_unkeepable_parse_is_parsed_again(store, monkeypatch):
    text = "a: 1\n" + "".join(f"k{i}: [1, 2.5, true, null, text]\n" for i in range(200))
    data = _fast_parse(text)
    (kept,) = store.glob("*.marshal")
    good = kept.read_bytes()
    # Not marshal data, cut short, one byte changed: none is loaded (the kept digest no longer matches).
    for damaged in (b"\x00 not marshal", good[: len(good) // 2], good[:-1] + bytes([good[-1] ^ 1])):
        kept.write_bytes(damaged)
        assert yaml_io._read_parsed(kept) is _UNPARSED
        assert _fast_parse(text) == data
        assert kept.read_bytes() == good  # written anew
    # A date is not kept (marshal holds no dates): parsed every time, the same answer.
    dated = "day: 2026-12-03\n" + "".join(f"x{i}: 1\n" for i in range(1000))
    assert _fast_parse(dated) == yaml.safe_load(dated)
    assert len(list(store.glob("*.marshal"))) == 1


def test_an_unwritable_cache_or_a_switched_off_one_parses_as_before(tmp_path, monkeypatch):
    blocked = tmp_path / "file"
    blocked.write_text("a file where the cache folder would be")
    monkeypatch.setenv("SCONE_BT_CACHE", str(blocked))
    text = "".join(f"k{i}: {i}\n" for i in range(500))
    assert _fast_parse(text) == yaml.safe_load(text)
    monkeypatch.setenv("SCONE_BT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv(yaml_io.YAML_CACHE_ENV, "0")
    assert _fast_parse(text) == yaml.safe_load(text)
    assert not (tmp_path / "cache").exists()


def test_a_syntax_error_is_never_kept(store):
    text = "a: [1, 2\n" + "b: 1\n" * 1000
    assert _fast_parse(text) is _UNPARSED
    assert not store.exists() or not list(store.glob("*.marshal"))


@pytest.mark.parametrize(
    "value, off", [("0", True), ("off", True), ("FALSE", True), ("1", False), ("", False)]
)
def test_one_rule_switches_a_disk_cache_off(monkeypatch, value, off):
    from scone_bt.resources import cache_switched_off

    monkeypatch.setenv("SCONE_BT_SOME_CACHE", value)
    assert cache_switched_off("SCONE_BT_SOME_CACHE") is off


@pytest.mark.parametrize("libyaml", [True, False])
def test_a_repeated_key_is_one_line_naming_both_lines_and_1e_minus_5_is_a_number(
    store, tmp_path, monkeypatch, libyaml
):
    if not libyaml:  # PyYAML built without libyaml: the pure-Python loader decides alone
        monkeypatch.setattr(yaml_io, "_loaders", lambda: (None, yaml_io._strict(yaml.SafeLoader)))
    tree = tmp_path / "tree.yaml"
    tree.write_text(
        "parameters:\n  gate: paper\n  target_failure_rate: 15e-2\n  gate: budget\n", encoding="utf-8"
    )
    with pytest.raises(ConfigError) as info:
        read_yaml(tree)
    assert str(info.value) == (
        f"{tree}: line 4 is not valid YAML (the key 'gate' is given twice, first on line 2)"
    )
    tree.write_text(
        "parameters:\n  target_failure_rate: 15e-2\n  solver_residual: -1E-5\n  name: '1e-5'\n", "utf-8"
    )
    assert read_yaml(tree) == {
        "parameters": {"target_failure_rate": 0.15, "solver_residual": -1e-05, "name": "1e-5"}
    }
    # a merge key (<<), a chain of merges, the same key in two mappings, 1 and '1' are not repeats
    tree.write_text("a: &base {x: 1}\nb:\n  <<: *base\n  x: 2\nc: {x: 3}\n", encoding="utf-8")
    assert read_yaml(tree) == {"a": {"x": 1}, "b": {"x": 2}, "c": {"x": 3}}
    chain = "d: &d {s: 1}\np:\n  f: &f\n    <<: *d\n    s: 2\ng:\n  <<: *f\n  s: 3\nk: {1: a, '1': b}\n"
    tree.write_text(chain, encoding="utf-8")
    assert read_yaml(tree) == {"d": {"s": 1}, "p": {"f": {"s": 2}}, "g": {"s": 3}, "k": {1: "a", "1": "b"}}
    tree.write_text("k:\n  ~: a\n  null: b\n", encoding="utf-8")  # the same key, None, spelt twice
    with pytest.raises(
        ConfigError, match=r"line 3 is not valid YAML \(the key None is given twice, first on line 2\)"
    ):
        read_yaml(tree)


def test_a_parse_kept_under_the_old_rules_is_not_reused(store):
    text = "a: 1e-5\n" + "# padding\n" * (yaml_io.CACHED_MIN_CHARS // 10 + 1)
    assert _fast_parse(text) == {"a": 1e-05}
    assert [p.name for p in store.glob("*.marshal")] == [yaml_io._parsed_path(text).name]  # type: ignore[union-attr]
