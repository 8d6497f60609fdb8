"""scone-bench's IF commands: building states from a corpus file, and one-line errors."""

from __future__ import annotations

import json

import pytest

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


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--limit", "-1"], "--limit -1: must be 0 (every state) or a positive number of states"),
        (
            ["--embedders", "minilm,onehot"],
            "--embedders minilm,onehot: unknown IF embedder 'onehot'; valid: <model directory>, finetuned:<dir>, "
            "glove, minilm, mpnet, mpnet-ft",
        ),
        (["--embedders", "nosuch"], "--embedders nosuch: unknown IF embedder 'nosuch'; valid: "),
        (["--ticc-embedder", "nosuch"], "--ticc-embedder nosuch: unknown IF embedder 'nosuch'; valid: "),
        (["--simulations", "0"], "--simulations 0: must be an integer in 1..1000000000"),
    ],
)
def test_bad_if_options_are_refused_before_the_states_are_read(tmp_path, capsys, argv, message) -> None:
    missing = str(tmp_path / "nope.jsonl")  # reading it would be a different error
    assert main(["if", "--states", missing, "--train", missing, *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"scone-bench: {message}") and "\n" not in err


def test_if_outputs_and_dev_file_are_checked_before_any_scoring(tmp_path, capsys) -> None:
    """A --save-finetuned that could not be written failed after the scoring and the fine-tuning; a --dev that
    does not exist was skipped, and the stop rule chosen without it."""
    missing = str(tmp_path / "nope.jsonl")  # reading it would be a different error
    taken = tmp_path / "notes.txt"
    taken.write_text("mine\n")
    cases = [
        (["--save-finetuned", str(taken)], f"--save-finetuned {taken}: is a file, not a folder"),
        (
            ["--save-finetuned", str(tmp_path / "head"), "--no-finetune"],
            "--save-finetuned: nothing is fine-tuned",
        ),
        (["--dev", str(tmp_path / "dev.jsonl")], f"--dev {tmp_path / 'dev.jsonl'}: no such file"),
        (
            ["--save-finetuned", str(tmp_path)],
            f"--save-finetuned {tmp_path}: holds other files than a fine-tuned",
        ),
    ]
    for argv, message in cases:
        assert main(["if", "--states", missing, "--train", missing, *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"scone-bench: {message}") and "\n" not in err, err
    assert taken.read_text() == "mine\n"


def test_every_if_embedder_the_message_lists_is_accepted() -> None:
    from scone_bt.errors import UnknownNameError
    from scone_bt.instruction_following.bench import check_embedders

    with pytest.raises(UnknownNameError) as err:
        check_embedders(["nosuch"])
    names = [n for n in err.value.valid if not n.startswith(("<", "finetuned:"))]
    assert names and "onehot" not in names
    check_embedders(names)


def _states_files(folder) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.glob("*.jsonl"))}


def test_if_states_never_silently_replaces_other_states(tmp_path, hummus, pancakes, capsys) -> None:
    out, corpus = tmp_path / "if", _corpus(tmp_path, hummus, pancakes)
    argv = ["if-states", "--out", str(out), "--corpus", str(corpus), "--distractors", "2"]
    assert main([*argv, "--seed", "0"]) == 0
    first = _states_files(out)
    assert sorted(first) == ["dev.jsonl", "pdr_mentions.jsonl", "test.jsonl", "train.jsonl"]
    capsys.readouterr()
    assert main([*argv, "--seed", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert f"--out {out}:" in err and "other states than this build" in err and "--force" in err
    assert "\n" not in err and "Traceback" not in err
    assert _states_files(out) == first
    assert main([*argv, "--seed", "0"]) == 0  # the same states again: nothing to refuse
    assert _states_files(out) == first
    assert main([*argv, "--seed", "1", "--force"]) == 0
    assert _states_files(out) != first
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


def test_if_states_checks_out_before_reading_the_corpus(tmp_path, capsys) -> None:
    missing = str(tmp_path / "no_corpus.jsonl")
    a_file = tmp_path / "a_file"
    a_file.write_text("mine\n")
    out = tmp_path / "if"
    out.mkdir()
    (out / "train.jsonl").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    for folder, message in ((a_file, "is a file, not a folder"), (out, "exists and is not a text file")):
        assert main(["if-states", "--out", str(folder), "--corpus", missing]) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and "\n" not in err
    assert (
        out / "train.jsonl"
    ).read_bytes() == b"\x89PNG\r\n\x1a\n\x00\x00" and a_file.read_text() == "mine\n"


def test_if_states_help_documents_force(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["if-states", "--help"])
    assert "--force" in capsys.readouterr().out


def test_a_folder_holding_an_earlier_head_may_be_saved_to_again(tmp_path, capsys) -> None:
    """A rerun replaces its own output: the next error is the missing states file, not the folder."""
    folder = tmp_path / "head"
    folder.mkdir()
    for name in ("finetuned.json", "head.safetensors"):
        (folder / name).write_text("earlier")
    missing = str(tmp_path / "nope.jsonl")
    assert main(["if", "--states", missing, "--train", missing, "--save-finetuned", str(folder)]) == 2
    assert capsys.readouterr().err.startswith("scone-bench: states file not found")
