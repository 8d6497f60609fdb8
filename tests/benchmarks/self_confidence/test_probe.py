"""`scone-bench sc probe`: out-of-fold attribute probes, the ceilings, the report and its one-line errors."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.probe import (
    ProbeOptions,
    ProductAttributes,
    probe_attributes,
    product_attributes,
)
from scone_bt.cli.bench import main
from scone_bt.errors import ConfigError


def _attrs(n: int = 120, seed: int = 0) -> ProductAttributes:
    rng = np.random.default_rng(seed)
    families = ("cans", "bags", "jars")
    return ProductAttributes(
        names=tuple(f"product {i:03d}" for i in range(n)),
        width=rng.uniform(0.03, 0.12, n),
        mass=rng.uniform(0.05, 1.2, n),
        glass=rng.random(n) < 0.3,
        family=tuple(families[i % 3] for i in range(n)),
    )


def test_a_text_that_encodes_the_attributes_is_read_off():
    attrs = _attrs()
    rng = np.random.default_rng(1)
    family_code = np.array([[f == g for g in ("cans", "bags", "jars")] for f in attrs.family], dtype=float)
    vectors = np.column_stack([attrs.width * 20, attrs.mass, attrs.glass * 1.0, family_code])
    vectors = np.hstack([vectors * 3, rng.normal(0, 0.01, (len(attrs.names), 5))])
    probe, predicted = probe_attributes("informative", vectors, attrs, ProbeOptions(folds=4))
    assert probe.products == 120
    assert probe.wide_auroc > 0.95 and probe.heavy_auroc > 0.95 and probe.glass_auroc > 0.95
    assert probe.width_r2 > 0.9 and probe.mass_r2 > 0.9
    assert probe.family_accuracy > 0.95 and probe.family_majority == pytest.approx(1 / 3)
    assert predicted.shape == (120, 3)
    assert np.corrcoef(predicted[:, 0], attrs.width)[0, 1] > 0.95


def test_scores_are_out_of_fold_a_product_s_own_column_teaches_nothing():
    # one-hot texts: in-sample the probe would be perfect; out of fold each product's column was never seen
    attrs = _attrs()
    probe, predicted = probe_attributes("identity", np.eye(len(attrs.names)), attrs, ProbeOptions(folds=5))
    assert 0.3 < probe.wide_auroc < 0.7 and 0.3 < probe.glass_auroc < 0.7
    assert probe.width_r2 < 0.05 and probe.mass_r2 < 0.05
    assert probe.family_accuracy <= probe.family_majority + 0.05


def test_a_seeded_probe_repeats_and_the_seed_changes_the_folds():
    attrs = _attrs()
    vectors = np.random.default_rng(3).normal(size=(len(attrs.names), 8)) + attrs.width[:, None] * 10
    a = probe_attributes("x", vectors, attrs, ProbeOptions(seed=0))
    b = probe_attributes("x", vectors, attrs, ProbeOptions(seed=0))
    c = probe_attributes("x", vectors, attrs, ProbeOptions(seed=1))
    assert a[0] == b[0] and np.array_equal(a[1], b[1])
    assert not np.array_equal(a[1], c[1])


def test_a_fold_with_one_class_in_training_scores_a_constant_not_its_base_rate():
    # one glass product in 40: the fold that tests it trains on none, and scores its 8 products 0.5
    attrs = _attrs(40)
    attrs = ProductAttributes(attrs.names, attrs.width, attrs.mass, np.arange(40) == 0, attrs.family)
    probe, predicted = probe_attributes("noise", np.random.default_rng(0).normal(size=(40, 4)), attrs)
    assert predicted[0, 2] == 0.5 and int(np.sum(predicted[:, 2] == 0.5)) == 8
    assert 0.0 <= probe.glass_auroc <= 1.0


def test_bad_options_and_shapes_are_config_errors():
    with pytest.raises(ConfigError, match="folds"):
        ProbeOptions(folds=1)
    with pytest.raises(ConfigError, match="positive"):
        ProbeOptions(wide_m=0.0)
    with pytest.raises(ConfigError, match="vectors"):
        probe_attributes("x", np.zeros((3, 2)), _attrs(), ProbeOptions())


def test_the_kitchen_catalogue_attributes():
    attrs = product_attributes()
    assert len(attrs.names) == len(set(attrs.names)) > 500
    row = dict(zip(attrs.names, range(len(attrs.names)), strict=True))
    assert attrs.glass[row["olive oil"]] and not attrs.glass[row["flour"]]
    assert attrs.family[row["flour"]] == "bags" and attrs.mass[row["flour"]] == pytest.approx(1.01)
    with pytest.raises(ConfigError, match="not a product"):
        attrs.rows(["flour", "not a product"], "my.csv")


def _write(
    directory: Path, products: list[str], attrs: ProductAttributes, n: int = 2, rows: int = 100
) -> Path:
    """Datasets where a product fails exactly when it is wider than 7.2 cm."""
    directory.mkdir(parents=True, exist_ok=True)
    width = dict(zip(attrs.names, attrs.width, strict=True))
    for d in range(n):
        rng = np.random.default_rng(10 + d)
        with (directory / f"p{d:02d}.csv").open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["index", "action", "object", "outcome"])
            for i in range(rows):
                p = products[int(rng.integers(len(products)))]
                w.writerow([i, f"Put {p} on table", p, "failure" if width.get(p, 0.0) > 0.072 else "success"])
    return directory


def test_probe_command_writes_the_report_and_the_true_attributes_beat_one_hot_text(tmp_path, capsys):
    attrs = product_attributes()
    products = list(attrs.names[::7])
    data, out = _write(tmp_path / "data", products, attrs), tmp_path / "out"
    argv = [
        "sc",
        "probe",
        "--data",
        str(data),
        "--embedders",
        "onehot",
        "--estimators",
        "knn",
        "--folds",
        "3",
    ]
    assert main([*argv, "--out", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads((out / "self_confidence_probe.json").read_text())
    assert printed["catalogue_products"] == len(attrs.names)
    assert [p["embedder"] for p in printed["probes"]] == ["onehot"]
    assert 0.3 < printed["probes"][0]["wide_auroc"] < 0.7  # a name's own column says nothing of a new product
    a1 = {r["features"]: r for r in printed["ceilings"]["algorithm1"]}
    assert set(a1) == {
        "family one-hot (true)",
        "width, mass, glass (true)",
        "width, mass, glass from onehot text",
    }
    true, text = a1["width, mass, glass (true)"]["auc"], a1["width, mass, glass from onehot text"]["auc"]
    assert true["mean"] > 0.9 and true["mean"] > text["mean"] + 0.1
    assert len(true["per_dataset"]) == 2
    assert set(printed["ceilings"]) == {"algorithm1", "novel_products"}
    md = (out / "self_confidence_probe.md").read_text()
    assert "| onehot |" in md and "## Ceilings, Novel products" in md
    assert main(argv) == 0  # a seeded run repeats exactly
    again = json.loads(capsys.readouterr().out)
    again.pop("timing_s"), printed.pop("timing_s")
    assert again == printed


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--estimators", "eps-knn"], "eps-knn"),
        (["--folds", "1"], "--folds"),
        (["--wide-m", "nan"], "--wide-m"),
        (["--embedders", "mpnt"], "minilm"),  # a typo is an error, not a skipped embedder
    ],
)
def test_probe_bad_options_are_one_line_errors(tmp_path, capsys, extra, message):
    attrs = product_attributes()
    data = _write(tmp_path / "data", list(attrs.names[:30]), attrs)
    assert main(["sc", "probe", "--data", str(data), "--embedders", "onehot", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err and "Traceback" not in err


def test_a_product_missing_from_the_catalogue_is_named_before_anything_runs(tmp_path, capsys):
    attrs = product_attributes()
    data = _write(tmp_path / "data", [*attrs.names[:10], "moon cheese"], attrs)
    assert main(["sc", "probe", "--data", str(data), "--embedders", "onehot"]) == 2
    err = capsys.readouterr().err.strip()
    assert "moon cheese" in err and "--catalogue" in err and "\n" not in err


def test_a_user_catalogue_is_probed_with_the_shop(tmp_path, user_catalogue, capsys):
    mine = user_catalogue(tmp_path)
    tins = ["smoked paprika tin", "saffron tin", "matcha tin"]
    attrs = product_attributes(catalogues=[mine])
    assert set(tins) <= set(attrs.names) and attrs.family[attrs.names.index("matcha tin")] == "my tins"
    data = _write(tmp_path / "data", [*tins, *attrs.names[:20]], attrs)
    argv = ["sc", "probe", "--data", str(data), "--embedders", "onehot", "--estimators", "knn"]
    assert main(argv) == 2  # without the user's file its tins are unknown
    assert "smoked paprika tin" in capsys.readouterr().err
    assert main([*argv, "--catalogue", str(mine)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["catalogue_products"] == len(attrs.names) == len(product_attributes().names) + 3


def test_probe_out_and_name_are_checked_before_anything_runs(tmp_path, capsys, monkeypatch):
    import scone_bt.benchmarks.self_confidence.probe as probe

    attrs = product_attributes()
    data = _write(tmp_path / "data", list(attrs.names[:30]), attrs)
    (data / "README.md").write_text("# the datasets\n")

    def boom(*args, **kwargs):
        raise AssertionError("the probe ran before --out and --name were checked")

    monkeypatch.setattr(probe, "product_attributes", boom)
    argv = ["sc", "probe", "--data", str(data), "--embedders", "onehot"]
    a_file = tmp_path / "notes.txt"
    a_file.write_text("mine\n")
    for extra, message in (
        (["--out", str(data), "--name", "README"], f"{data / 'README.md'}: is the --data input"),
        (["--out", str(a_file)], "is a file, not a folder"),
    ):
        assert main([*argv, *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and "\n" not in err and "Traceback" not in err
    assert (data / "README.md").read_text() == "# the datasets\n" and a_file.read_text() == "mine\n"
