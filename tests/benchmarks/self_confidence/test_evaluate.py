"""`scone-bench sc evaluate` end to end on small datasets: the JSON shape, Markdown and PNGs, one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.evaldata import load_eval_datasets
from scone_bt.benchmarks.self_confidence.evaluate import GridInputs, embed_datasets, evaluate_grid_pair
from scone_bt.benchmarks.self_confidence.protocols import EvalOptions, Protocol
from scone_bt.benchmarks.self_confidence.report_types import load_report
from scone_bt.cli.bench import main


def _numbers(report: dict) -> dict:
    """The protocols' numbers without wall times."""
    return {
        p: [{k: v for k, v in e.items() if k != "pair_wall_s"} for e in es]
        for p, es in report["protocols"].items()
    }


SMALL = ["--steps", "10,20,30", "--lofo-steps", "30", "--n-test", "10", "--workers", "1", "--no-cell-cache"]


def test_evaluate_prints_and_writes_the_documented_shape(sc_data, tmp_path, capsys):
    data, out = sc_data(n_datasets=2, rows=40), tmp_path / "out"
    argv = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot,glove", "--estimators", "knn"]
    argv += ["eps-knn", "grounded-knn", "--out", str(out), "--json", str(tmp_path / "r.json"), *SMALL]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    assert (
        printed
        == json.loads((tmp_path / "r.json").read_text())
        == json.loads((out / "self_confidence.json").read_text())
    )
    assert load_report(out / "self_confidence.json") == printed  # the file fits report_types.EvaluationReport
    assert set(printed["protocols"]) == {"algorithm1", "novel_products", "leave_family_out"}
    for protocol, entries in printed["protocols"].items():
        assert [(e["embedder"], e["estimator"]) for e in entries] == [
            (emb, est) for emb in ("onehot", "glove") for est in ("knn", "eps-knn", "grounded-knn")
        ]
        for e in entries:
            assert {"embedder", "estimator", "auc", "auroc", "brier", "ece", "n_test", "reliability"} <= set(
                e
            )
            assert (
                set(e["auc"]) == {"mean", "std", "per_dataset", "dataset_index"}
                and 0.0 <= e["auc"]["mean"] <= 1.0
            )
            assert len(e["auc"]["per_dataset"]) == 2
            assert np.mean(e["auc"]["per_dataset"]) == pytest.approx(e["auc"]["mean"])
            assert len(e["reliability"]) == 10
        assert ("robot" in entries[1]) == (protocol == "algorithm1")  # eps-knn: the robots' behaviour
    assert printed["protocols"]["algorithm1"][0]["n_test"] == 20
    md = (out / "self_confidence.md").read_text()
    assert "## Against the targets" in md and "| onehot |" in md and "## ε-greedy" in md
    for png in ("algorithm1_curves", "novel_products_curves", "leave_family_out_curves", "reliability"):
        assert (out / f"self_confidence_{png}.png").stat().st_size > 1000
    # a seeded run repeats exactly
    assert main(argv) == 0
    again = json.loads(capsys.readouterr().out)
    assert _numbers(again) == _numbers(printed)


def test_protocols_and_estimators_are_selected(sc_data, capsys):
    data = sc_data(n_datasets=1, rows=40)
    argv = ["sc", "evaluate", "--data", str(data), "--protocols", "novel_products", "--embedders", "onehot"]
    assert main([*argv, "--estimators", "xgboost", *SMALL]) == 0
    report = json.loads(capsys.readouterr().out)
    assert list(report["protocols"]) == ["novel_products"]
    assert [e["estimator"] for e in report["protocols"]["novel_products"]] == ["xgb"]


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [
        ("--protocols", "loo", "unknown protocol 'loo'"),
        ("--estimators", "catboost", "unknown estimator 'catboost'"),
        ("--embedders", "word2vec", "unknown embedder 'word2vec'"),
    ],
)
def test_bad_names_are_one_line_errors_with_the_valid_list(sc_data, capsys, flag, value, message):
    data = sc_data(n_datasets=1, rows=40)
    assert main(["sc", "evaluate", "--data", str(data), flag, value, *SMALL]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "valid" in err and len(err.splitlines()) == 1
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("kitchen", "message"),
    [
        ("nosuch", "--kitchen nosuch: unknown kitchen; valid: kitchen"),
        (
            "nofile.yaml",
            "--kitchen nofile.yaml: no such file; give a kitchen name (valid: kitchen) or a path to a kitchen YAML file",
        ),
    ],
)
def test_a_bad_kitchen_is_refused_before_the_data_is_read(tmp_path, capsys, kitchen, message):
    missing = tmp_path / "missing"  # reading the data first would be another error
    assert (
        main(
            ["sc", "evaluate", "--data", str(missing), "--kitchen", kitchen, "--embedders", "onehot", *SMALL]
        )
        == 2
    )
    assert capsys.readouterr().err.strip() == f"scone-bench: {message}"


def test_an_empty_or_missing_data_dir_is_a_one_line_error(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    for folder in (tmp_path / "empty", tmp_path / "missing"):
        assert main(["sc", "evaluate", "--data", str(folder), "--embedders", "onehot", *SMALL]) == 2
        err = capsys.readouterr().err.strip()
        assert str(folder) in err and len(err.splitlines()) == 1


def test_grounded_knn_sees_the_context_that_decides_the_outcome(sc_data):
    # In the fixture, bags fail when crowded: only the context tells a crowded bag from a free one.
    datasets = load_eval_datasets(sc_data(n_datasets=3, rows=60))
    vocab = sorted({a for d in datasets for a in d.actions})
    onehot = embed_datasets(datasets, lambda texts: np.eye(len(vocab))[[vocab.index(t) for t in texts]])
    opts = EvalOptions(n_test=20, steps=(20, 40), lofo_steps=(40,))
    inputs = GridInputs(tuple(datasets), {"onehot": onehot}, opts, (Protocol.ALGORITHM1,))
    plain = evaluate_grid_pair(("onehot", "lgbm"), inputs)
    grounded = evaluate_grid_pair(("onehot", "grounded-lgbm"), inputs)
    assert np.mean(grounded.auc) > np.mean(plain.auc)


def test_cached_cells_give_the_same_report(sc_data, tmp_path, capsys):
    data = sc_data(n_datasets=2, rows=40)
    argv = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot", "--estimators", "knn,eps-knn"]
    argv += ["--cache-dir", str(tmp_path / "cache"), *SMALL[:-1]]
    assert main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    assert len(list((tmp_path / "cache" / "sc_cells").glob("*.json"))) == 4  # 2 pairs × 2 datasets
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["protocols"] == first["protocols"]  # wall times too: cached


def test_a_base_estimator_computed_with_its_calibrated_variant_scores_as_alone(sc_data, tmp_path, capsys):
    # grounded-knn's cells come out of grounded-knn-cal's fits when both are in the grid: the same numbers as a
    # grid with grounded-knn alone, and a cache that holds both cells.
    data = sc_data(n_datasets=2, rows=40)
    argv = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot", *SMALL]
    assert main([*argv, "--estimators", "grounded-knn"]) == 0
    alone = _numbers(json.loads(capsys.readouterr().out))
    assert main([*argv, "--estimators", "grounded-knn-cal,grounded-knn"]) == 0
    both = _numbers(json.loads(capsys.readouterr().out))
    for p, entries in alone.items():
        assert [e for e in both[p] if e["estimator"] == "grounded-knn"] == entries
        assert [e["estimator"] for e in both[p]] == ["grounded-knn-cal", "grounded-knn"]
    cached = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot", *SMALL[:-1]]
    cached += ["--cache-dir", str(tmp_path / "cache"), "--estimators", "grounded-knn-cal,grounded-knn"]
    assert main(cached) == 0
    assert _numbers(json.loads(capsys.readouterr().out)) == both
    assert len(list((tmp_path / "cache" / "sc_cells").glob("*.json"))) == 4  # 2 estimators × 2 datasets


@pytest.fixture
def no_evaluation(monkeypatch):
    """The evaluation must not start: --out and --name are checked before it."""
    import scone_bt.benchmarks.self_confidence.evaluate as evaluate

    def boom(*args, **kwargs):
        raise AssertionError("the evaluation ran before --out and --name were checked")

    monkeypatch.setattr(evaluate, "_embed_all", boom)


def _refused(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    return err


def test_a_report_never_replaces_a_file_of_the_data_folder(sc_data, capsys, no_evaluation):
    data = sc_data(n_datasets=1, rows=40)
    (data / "README.md").write_text("# the shipped datasets\n")
    (data / "generation.json").write_text('{"runs": []}\n')
    argv = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot", "--out", str(data), *SMALL]
    for name, file in (("README", "README.md"), ("generation", "generation.json")):
        err = _refused(capsys, [*argv, "--name", name])
        assert str(data / file) in err and "--data input" in err
    assert (data / "README.md").read_text() == "# the shipped datasets\n"
    assert (data / "generation.json").read_text() == '{"runs": []}\n'
    assert sorted(p.name for p in data.iterdir()) == ["README.md", "generation.json", "p00_robot.csv"]


def test_a_bad_out_or_name_is_refused_before_the_evaluation(sc_data, tmp_path, capsys, no_evaluation):
    data = sc_data(n_datasets=1, rows=40)
    argv = ["sc", "evaluate", "--data", str(data), "--embedders", "onehot", *SMALL]
    a_file = tmp_path / "report.txt"
    a_file.write_text("my notes\n")
    err = _refused(capsys, [*argv, "--out", str(a_file)])
    assert f"--out {a_file}: is a file, not a folder" in err and a_file.read_text() == "my notes\n"
    out = tmp_path / "out"
    out.mkdir()
    (out / "self_confidence.json").write_text("my notes, not JSON\n")
    err = _refused(capsys, [*argv, "--out", str(out)])
    assert "self_confidence.json: exists and is not a JSON file" in err
    (out / "x.json").write_text("{}\n")
    (out / "x_reliability.png").write_text("not a picture\n")
    err = _refused(capsys, [*argv, "--out", str(out), "--name", "x"])
    assert "x_reliability.png: exists and is not an image" in err
    assert (out / "x_reliability.png").read_text() == "not a picture\n"
    err = _refused(capsys, [*argv, "--out", str(out), "--name", "../x"])
    assert "--name '../x'" in err
