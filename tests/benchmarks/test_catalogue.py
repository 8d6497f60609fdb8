"""scone-bench catalogue on a small corpus written here (the real corpus run is the benchmark itself)."""

from __future__ import annotations

import json

from scone_bt.benchmarks.catalogue import label_item, run_catalogue_benchmark
from scone_bt.cli.bench import main

RECIPES = [
    {
        "id": "nw:test/Toast",
        "title": "Toast",
        "ingredients": ["2 slices bread", "1 Tbsp unsalted butter, softened", "1 cup water"],
        "ingredients_structured": [
            {"name": "bread", "quantities": ["2 slices"]},
            {"name": "unsalted butter, softened", "quantities": ["1 Tbsp"]},
            {"name": "water", "quantities": ["1 cup"]},
        ],
        "steps": ["Toast the bread.", "Spread the butter."],
    },
    {
        "id": "pdr:test-moon-cake",
        "title": "Moon cake",
        "ingredients": ["Six eggs.", "1 heaping tbsp Cumin", "a pinch of unobtainium", "cheesecloth"],
        "steps": ["Beat the eggs with the cumin.", "Strain through cheesecloth."],
    },
]


def _corpus(tmp_path):
    path = tmp_path / "recipes.jsonl"
    path.write_text("\n".join(json.dumps(r) for r in RECIPES) + "\n")
    labels = tmp_path / "labels.jsonl"
    labels.write_text(
        json.dumps({"line": "Six eggs.", "item": "eggs"})
        + "\n"
        + json.dumps({"line": "2 Onions", "item": "leek"})
    )
    return path, labels


def test_label_rule_keeps_the_item_only():
    assert label_item("unsalted butter, softened") == "unsalted butter"
    assert label_item("cinnamon (optional)") == "cinnamon"
    assert label_item("spinach or kale") == "spinach"
    assert label_item("chopped celery") == "celery"


def test_figures_on_a_small_corpus(tmp_path, kitchen_cfg):
    corpus, labels = _corpus(tmp_path)
    r = run_catalogue_benchmark(corpus=corpus, pdr_labels=labels)
    assert r["products"] == len(kitchen_cfg.catalogue) and r["families"] >= 12
    assert (r["normalisation_accuracy"], r["normalisation_lines"]) == (1.0, 3)
    assert (r["pdr_sample_accuracy"], r["pdr_sample_lines"]) == (0.5, 2)
    assert r["mentions"] == 7
    assert r["mentions_by_class"] == {"stocked": 4, "water": 1, "tool": 1, "unstocked": 1, "nothing": 0}
    assert r["mention_coverage"] == round(6 / 7, 4)
    assert r["recipes_fully_stocked_fraction"] == 0.5  # the moon cake lacks unobtainium
    assert r["recipes_fit_shelf_fraction"] == 1.0
    assert r["top_unstocked_items"] == {"unobtainium": 1}


def test_cli_prints_and_writes_json(tmp_path, capsys):
    corpus, labels = _corpus(tmp_path)
    out = tmp_path / "out.json"
    argv = ["catalogue", "--corpus", str(corpus), "--pdr-labels", str(labels), "--json", str(out)]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    assert json.loads(out.read_text()) == printed
    assert {"products", "families", "normalisation_accuracy", "mention_coverage"} <= printed.keys()
    assert {
        "recipes_fully_stocked_fraction",
        "recipes_fit_shelf_fraction",
        "pdr_sample_accuracy",
    } <= printed.keys()


def test_user_catalogue_changes_coverage(tmp_path):
    corpus, labels = _corpus(tmp_path)
    mine = tmp_path / "mine.yaml"
    mine.write_text(
        "family: exotic\nsource: invented for a test\nproducts:\n  - {name: unobtainium, shape: box, size: [0.05,"
        " 0.05, 0.05], mass: 0.1, friction: 0.5, material: paper, rgba: [1, 0, 1, 1], marker_id: 990}\n"
    )
    r = run_catalogue_benchmark(catalogues=(str(mine),), corpus=corpus, pdr_labels=labels)
    assert r["recipes_fully_stocked_fraction"] == 1.0 and r["mention_coverage"] == 1.0


def test_missing_corpus_is_one_line(tmp_path, capsys):
    assert main(["catalogue", "--corpus", str(tmp_path / "none.jsonl")]) == 2
    err = capsys.readouterr().err
    assert "recipe corpus not found" in err and err.count("\n") == 1
