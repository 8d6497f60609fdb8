"""scone-bench's IF commands: building states from a corpus file, and one-line errors."""

from __future__ import annotations

import json

from scone_bt.cli.bench import main
from scone_bt.instruction_following.states import load_states


def _corpus(tmp_path, hummus, pancakes):
    path = tmp_path / "recipes.jsonl"
    with path.open("w") as fh:
        for r in (hummus, pancakes):
            record = {
                "id": r.id,
                "title": r.title,
                "ingredients": list(r.ingredients),
                "steps": list(r.steps),
                "step_ingredients": [list(s) for s in r.step_ingredients],
            }
            fh.write(json.dumps(record) + "\n")
    return path


def test_if_states_builds_split_files(tmp_path, hummus, pancakes, capsys) -> None:
    out = tmp_path / "if"
    assert (
        main(
            [
                "if-states",
                "--out",
                str(out),
                "--corpus",
                str(_corpus(tmp_path, hummus, pancakes)),
                "--distractors",
                "2",
            ]
        )
        == 0
    )
    report = json.loads(capsys.readouterr().out)
    total = sum(report["states"][s] for s in ("train", "dev", "test"))
    assert total == 5  # hummus: 3 steps need items; pancakes: 2
    loaded = [s for split in ("train", "dev", "test") for s in load_states(out / f"{split}.jsonl")]
    assert len(loaded) == total


def test_missing_states_file_is_one_line(tmp_path, capsys) -> None:
    assert main(["if", "--states", str(tmp_path / "nope.jsonl"), "--train", str(tmp_path / "t.jsonl")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("scone-bench: states file not found") and "\n" not in err
