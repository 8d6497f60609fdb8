"""The typed self-confidence report: the committed JSONs read back as EvaluationReports, unchanged, and a
malformed one is a one-line error naming the file and the key."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from scone_bt.benchmarks.self_confidence.report import evaluation_markdown, write_json
from scone_bt.benchmarks.self_confidence.report_types import load_report, report_from_json
from scone_bt.errors import ConfigError

RESULTS = Path(__file__).resolve().parents[3] / "docs" / "results"
COMMITTED = [
    RESULTS / f"self_confidence{suffix}.json" for suffix in ("", "_5orders", "_grounded", "_oracle")
]  # the sc evaluate reports (self_confidence_probe.json is sc probe's)


@pytest.mark.parametrize("path", COMMITTED, ids=lambda p: p.stem)
def test_a_committed_report_round_trips_byte_for_byte(path: Path, tmp_path: Path) -> None:
    report = load_report(path)
    out = tmp_path / path.name
    write_json(out, report)
    assert out.read_text() == path.read_text()
    assert evaluation_markdown(report, path.stem).startswith("#")


def _report() -> dict:
    return json.loads((RESULTS / "self_confidence.json").read_text())


def test_a_missing_key_names_the_file_and_the_key(tmp_path: Path) -> None:
    bad = _report()
    del bad["protocols"]["algorithm1"][0]["n_test"]
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(ConfigError) as err:
        load_report(path)
    message = str(err.value)
    assert "\n" not in message
    assert str(path) in message and "report.protocols.algorithm1[0].n_test: missing" in message


def test_a_value_of_the_wrong_type_names_the_key() -> None:
    bad = _report()
    bad["options"]["n_train"] = "100"
    with pytest.raises(ConfigError, match=r"^r\.json: .*report\.options\.n_train: expected a list, got str$"):
        report_from_json(bad, "r.json")


def test_text_that_is_not_json_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text("{not json")
    with pytest.raises(ConfigError, match="broken.json: cannot read") as err:
        load_report(path)
    assert "\n" not in str(err.value)


def test_older_reports_without_the_optional_keys_still_load() -> None:
    old = _report()
    old.pop("prior")
    for entry in old["protocols"]["algorithm1"]:
        entry.pop("ece_noise_floor", None)
        entry["auc"].pop("per_dataset", None)
    assert report_from_json(old)["embedders"] == old["embedders"]
