"""Large configuration files are kept parsed on disk: read back equal to a parse, never stale, never an error."""

from pathlib import Path

import pytest
import yaml

from scone_bt.config import yaml_io
from scone_bt.config.yaml_io import _UNPARSED, _fast_parse, read_yaml

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
    dated = "day: 2026-12-03\n" + "x: 1\n" * 1000
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
