"""``scone-bench perception``: runs with its defaults' shape on a small scene count and reports the issue's keys."""

from __future__ import annotations

import json

import pytest

from scone_bt.cli.bench import main


@pytest.mark.slow
def test_perception_benchmark_reports_accuracy_of_shelf_and_table(tmp_path, capsys):
    out = tmp_path / "perception.json"
    assert main(["perception", "--scenes", "1", "--objects", "6", "--noise", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert json.loads(capsys.readouterr().out) == report
    for key in ("recall_unoccluded", "precision", "position_error_median_m"):
        assert key in report and report[key] == report["default"][key]
    assert report["objects_per_scene"] == 6 and report["table_objects_per_scene"] == 3
    assert 0.0 <= report["recall_unoccluded"] <= 1.0 and report["precision"] > 0.9
    assert report["table"]["objects"] == 3  # the table camera is scored on the table's products
    assert set(report["resolutions"]) == {"320x240", "640x480"}


def test_default_object_count_fills_the_shelving(capsys):
    # More products than the shelving holds is a one-line error naming the valid range.
    assert main(["perception", "--scenes", "1", "--objects", "999"]) == 2
    err = capsys.readouterr().err
    assert "--objects 999: must be in 1-" in err and "Traceback" not in err


@pytest.mark.parametrize("noise", ["nan", "inf", "-1", "256"])
def test_noise_outside_the_pixel_scale_is_refused_before_the_kitchen_is_read(tmp_path, capsys, noise):
    broken = tmp_path / "broken.yaml"  # reading the kitchen first would be another error
    broken.write_text("[not a kitchen", encoding="utf-8")
    assert main(["perception", "--kitchen", str(broken), "--noise", "8", noise]) == 2
    assert capsys.readouterr().err == f"scone-bench: --noise {float(noise)}: must be a number in [0, 255]\n"


def test_each_engine_is_judged_by_its_own_targets():
    from scone_bt.benchmarks.perception import TARGETS, targets_for

    assert targets_for("sim") == TARGETS
    assert targets_for("mujoco")["position_error_median_m"] == 0.002  # the MuJoCo issue's ≤ 2 mm
    assert targets_for("mujoco")["recall_unoccluded"] == TARGETS["recall_unoccluded"]


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--table-objects", "1000"], "--table-objects 1000: must be in 0-35"),  # blamed --objects before
        (["--scenes", "0"], "--scenes 0: must be 1 or more"),
    ],
)
def test_each_count_names_its_own_flag(argv, line, capsys):
    assert main(["perception", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-bench: {line}") and err.count("\n") == 1, err
