"""`scone-models`: listing, the MPNet assembly steps (on a fake split archive), and one-line errors."""

from __future__ import annotations

import zipfile

import pytest

from scone_bt.cli.models import main
from scone_bt.embedding import install_mpnet, registry
from scone_bt.errors import ModelUnavailableError


def test_list_shows_every_embedder(capsys, tmp_path):
    assert main(["--cache-dir", str(tmp_path), "list"]) == 0
    out = capsys.readouterr().out
    for name in ("minilm", "mpnet", "glove", "onehot", "finetuned:<dir>"):
        assert name in out


def test_unknown_model_is_a_one_line_error(capsys):
    assert main(["install", "bge"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "valid: mpnet" in err


def test_embed_prints_similarities(capsys, tmp_path):
    assert main(["--cache-dir", str(tmp_path), "embed", "glove", "salt", "pepper"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "glove: 50-d" and lines[1].startswith("+1.000")


def _split_archive(tmp_path, pieces: int) -> list:
    archive = tmp_path / "model.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("all-mpnet-base-v2/modules.json", "[]")
        zf.writestr("all-mpnet-base-v2/config.json", "{}")
    data = archive.read_bytes()
    size = len(data) // pieces + 1
    parts = []
    for i in range(pieces):
        part = tmp_path / f"all-mpnet-base-v2.zip.{i + 1:03d}"
        part.write_bytes(data[i * size : (i + 1) * size])
        parts.append(part)
    return parts


def test_install_mpnet_concatenates_and_unzips(tmp_path, monkeypatch):
    parts = _split_archive(tmp_path, 5)
    monkeypatch.setattr(registry, "_mpnet_zip_parts", lambda: (parts, []))
    target = install_mpnet(tmp_path / "cache", log=lambda _: None)
    assert target == tmp_path / "cache" / "models" / "all-mpnet-base-v2"
    assert (target / "modules.json").read_text() == "[]"
    assert registry.mpnet_dir(tmp_path / "cache") == target
    assert [p.name for p in target.parent.iterdir()] == ["all-mpnet-base-v2"]  # no temporary left over


def test_install_mpnet_rejects_a_broken_archive(tmp_path, monkeypatch):
    parts = _split_archive(tmp_path, 5)
    parts[2].write_bytes(b"garbage")
    monkeypatch.setattr(registry, "_mpnet_zip_parts", lambda: (parts, []))
    with pytest.raises(ModelUnavailableError, match="valid zip"):
        install_mpnet(tmp_path / "cache", log=lambda _: None)
    assert not (tmp_path / "cache" / "models" / "all-mpnet-base-v2").exists()


def test_a_cache_dir_that_cannot_hold_the_model_is_one_line_before_pip_runs(tmp_path, capsys, monkeypatch):
    import scone_bt.embedding as embedding

    monkeypatch.setattr(embedding, "install_mpnet", lambda *a, **k: pytest.fail("pip ran"))
    a_file = tmp_path / "quick.yaml"
    a_file.write_text("a: 1\n")
    assert main(["--cache-dir", str(a_file), "install", "mpnet"]) == 2
    err = capsys.readouterr().err
    assert err == f"scone-models: --cache-dir {a_file}: is a file, not a folder; it is never overwritten\n"
    assert a_file.read_text() == "a: 1\n"


def test_a_file_given_as_the_cache_and_a_blank_text_are_one_line(tmp_path, capsys):
    """`list` with a file for its cache called every model missing; `embed` compared empty texts."""
    taken = tmp_path / "cache.txt"
    taken.write_text("mine\n")
    assert main(["--cache-dir", str(taken), "list"]) == 2
    assert capsys.readouterr().err == f"scone-models: --cache-dir {taken}: is a file, not a folder\n"
    assert main(["--cache-dir", str(tmp_path / "c"), "embed", "onehot", "salt", " "]) == 2
    assert capsys.readouterr().err == "scone-models: embed: text 2 of 2 is empty; give texts to compare\n"
    assert taken.read_text() == "mine\n"
