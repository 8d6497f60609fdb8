"""Every loader of a user file refuses a device, a FIFO and a file over its stated size with one line, before
reading it (issue 27: `--catalogue /dev/zero` read forever and grew to 10 GB)."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from scone_bt.benchmarks.self_confidence.dataset import read_dataset, read_records
from scone_bt.benchmarks.self_confidence.profiles import load_profile
from scone_bt.config import load_kitchen, load_robot, read_yaml
from scone_bt.config.catalogue import load_catalogue
from scone_bt.config.schema import MAX_DATA_FILE_BYTES, MAX_FILE_BYTES, read_text
from scone_bt.errors import SconeError
from scone_bt.recipes import load_recipe
from scone_bt.study.ratings_csv import load_ratings_csv
from scone_bt.tree import load_tree_spec

# (loader, file suffix, the limit its message must state)
LOADERS: dict[str, tuple[Callable[[Path], Any], str, str]] = {
    "kitchen": (load_kitchen, ".yaml", "16 MiB"),
    "catalogue": (lambda p: load_catalogue([p]), ".yaml", "16 MiB"),
    "recipe": (lambda p: load_recipe(str(p)), ".json", "16 MiB"),
    "tree": (load_tree_spec, ".yaml", "16 MiB"),
    "robot": (load_robot, ".yaml", "16 MiB"),
    "profile": (load_profile, ".yaml", "16 MiB"),
    "yaml": (read_yaml, ".yaml", "16 MiB"),
    "dataset CSV": (read_dataset, ".csv", "256 MiB"),
    "generator CSV": (read_records, ".csv", "256 MiB"),
    "ratings CSV": (load_ratings_csv, ".csv", "256 MiB"),
}


def _within(fn: Callable[[], Any], seconds: float = 30.0) -> BaseException | None:
    """Run fn in a thread; the exception it raised (None if it returned). A hang fails the test, not the suite."""
    out: list[BaseException | None] = []

    def run() -> None:
        try:
            fn()
            out.append(None)
        except BaseException as exc:  # noqa: BLE001 - handed back to the test
            out.append(exc)

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(seconds)
    assert not worker.is_alive(), "the loader hangs"
    return out[0]


def _one_line(exc: BaseException | None) -> str:
    assert isinstance(exc, SconeError), repr(exc)
    text = str(exc)
    assert "\n" not in text
    return text


@pytest.mark.parametrize("name", sorted(LOADERS))
def test_an_oversized_file_is_refused_unread(name, tmp_path):
    loader, suffix, limit = LOADERS[name]
    path = tmp_path / f"big{suffix}"
    size = MAX_DATA_FILE_BYTES + 1 if limit == "256 MiB" else MAX_FILE_BYTES + 1
    with path.open("wb") as f:  # sparse: no disk space, and nothing of it may be read
        f.truncate(size)
    text = _one_line(_within(lambda: loader(path)))
    assert str(path) in text and limit in text and "too large" in text


@pytest.mark.parametrize("name", sorted(LOADERS))
def test_a_fifo_is_refused_without_waiting_for_a_writer(name, tmp_path):
    loader, suffix, _ = LOADERS[name]
    path = tmp_path / f"pipe{suffix}"
    os.mkfifo(path)
    text = _one_line(_within(lambda: loader(path)))
    assert (
        str(path) in text
    )  # "is a FIFO", or "unknown kitchen ..." where only names in a folder are accepted


@pytest.mark.parametrize("name", sorted(LOADERS))
def test_a_device_is_refused(name):
    loader, _, _ = LOADERS[name]
    text = _one_line(_within(lambda: loader(Path("/dev/zero"))))
    assert "/dev/zero" in text


def test_the_one_reader_names_what_it_refused(tmp_path):
    assert "is a device" in _one_line(_within(lambda: read_text("/dev/zero")))
    os.mkfifo(tmp_path / "p")
    assert "is a FIFO" in _one_line(_within(lambda: read_text(tmp_path / "p")))
    assert "is a directory" in _one_line(_within(lambda: read_text(tmp_path)))


def test_scone_run_refuses_a_device_catalogue_before_the_kitchen(capsys):
    from scone_bt.cli.run import main

    code: list[int] = []
    assert _within(lambda: code.append(main(["--catalogue", "/dev/zero", "--max-ticks", "1"]))) is None
    out = capsys.readouterr()
    assert code == [2] and out.out == ""
    assert (
        out.err.strip()
        == "scone-run: error: --catalogue /dev/zero: is a device, not a regular file; give a file"
    )


def test_libyaml_reads_every_shipped_file_as_the_pure_python_parser_does():
    import yaml

    from scone_bt.config.yaml_io import _UNPARSED, _fast_parse

    root = Path(__file__).resolve().parents[2]
    files = [
        p
        for folder in ("robots", "perception", "trees", "recipes", "scenarios")
        for p in (root / folder).rglob("*.yaml")
    ]
    assert len(files) > 40
    for path in files:
        text = path.read_text(encoding="utf-8")
        fast = _fast_parse(text)
        assert fast is not _UNPARSED and fast == yaml.safe_load(text), path
