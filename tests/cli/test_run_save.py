"""scone-run --save writes a recording that rerun's own reader can open, with one entry per tree tick."""

from __future__ import annotations

import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.episode import EpisodeOptions, run_episode
from scone_bt.viz.readback import summarize_recording

pytestmark = pytest.mark.slow


def test_saved_episode_reads_back(tmp_path):
    path = tmp_path / "episode.rrd"
    options = EpisodeOptions(
        recipe="example:hummus",
        seed=1,
        distractors=2,
        max_ticks=150,
        save=path,
        behaviour=BehaviourOptions(seed=1),
    )
    summary = run_episode(options, printer=lambda _line: None)
    rec = summarize_recording(path)
    # Tick 0 holds the static scene; then one entry per tick of the tree.
    assert rec.num_ticks == summary.tree_ticks + 1
    assert rec.has_blueprint
    paths = set(rec.entity_paths)
    for expected in ("/world/camera", "/world/robot", "/world/objects", "/tree", "/recipe", "/affordances"):
        assert any(p == expected or p.startswith(expected + "/") for p in paths), expected


def test_save_never_replaces_a_yaml_file_even_with_force(tmp_path, capsys):
    """`--save catalogue.yaml --force` replaced a catalogue file with a recording."""
    from scone_bt.cli.run import main

    target = tmp_path / "cat.yaml"
    target.write_text("products: []\n")
    assert main(["--save", str(target), "--force", "--max-ticks", "1", "--quiet"]) == 2
    assert target.read_text() == "products: []\n"
    assert "is a YAML file" in capsys.readouterr().err


def test_an_empty_save_path_says_so(capsys):
    """`--save ""` said "--save .: is a folder"."""
    import pytest

    from scone_bt.cli.run import main

    with pytest.raises(SystemExit) as done:
        main(["--save", "", "--max-ticks", "1"])
    assert done.value.code == 2 and "an empty path; give a file or folder path" in capsys.readouterr().err
