"""The user documentation stays short and readable, and its reference pages come from the code: the README within
200 lines, no internal issue numbers in README.md or docs/, every page under docs/ in the site's navigation, and
the generated reference naming every command, subcommand and tree parameter the code defines."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))

import docs_reference  # noqa: E402  (tools/ is not a package)

ISSUE = re.compile(r"\bissues? ?#?\d+\b|\bissue\d+", re.IGNORECASE)


def test_readme_is_short_and_names_no_issue():
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; the history belongs in CHANGELOG.md"
    assert not [n for n, line in enumerate(lines, 1) if ISSUE.search(line)]


def test_docs_name_no_issue():
    hits = []
    for path in sorted((REPO / "docs").rglob("*")):
        if "issue" in path.name.lower():
            hits.append(str(path.relative_to(REPO)))
        if path.suffix in (".md", ".jsonl"):
            text = path.read_text(encoding="utf-8").splitlines()
            hits += [f"{path.relative_to(REPO)}:{n}" for n, line in enumerate(text, 1) if ISSUE.search(line)]
    assert not hits, f"internal issue numbers in the user documentation: {hits}"


def _nav_pages(node: object) -> list[str]:
    if isinstance(node, str):
        return [node]
    if isinstance(node, list):
        return [p for item in node for p in _nav_pages(item)]
    if isinstance(node, dict):
        return [p for value in node.values() for p in _nav_pages(value)]
    return []


def test_every_page_is_in_the_nav():
    # mkdocs.yml's one python tag (the mermaid fence) is not needed to read the nav
    text = (REPO / "mkdocs.yml").read_text(encoding="utf-8").replace("!!python/name:", "")
    config = yaml.safe_load(text)
    nav = set(_nav_pages(config["nav"]))
    generated = set(docs_reference.PAGES)
    missing_files = sorted(p for p in nav - generated if not (REPO / "docs" / p).is_file())
    assert not missing_files, f"mkdocs.yml names pages that do not exist: {missing_files}"
    pages = {str(p.relative_to(REPO / "docs")) for p in (REPO / "docs").rglob("*.md")}
    outside = sorted(p for p in pages - nav if not p.startswith("notes/"))
    assert not outside, f"pages missing from mkdocs.yml's nav: {outside}"


def test_cli_reference_has_every_subcommand():
    page = docs_reference.cli_page()
    for command, module, names in docs_reference.COMMANDS:
        for path, _ in docs_reference._walk(docs_reference._parser_of(module, names), command):
            assert f"usage: {path}" in page, path


def test_config_reference_has_every_tree_parameter_and_robot_key():
    from scone_bt.config.robot import RobotFile
    from scone_bt.config.tree_parameters import TreeParameters

    page = docs_reference.config_page()
    for model in (TreeParameters, RobotFile):
        for key in model.model_fields:
            assert f"| `{key}` |" in page, key
    # the model's own descriptions (the one declaration of each tree setting) describe the keys
    assert TreeParameters.model_fields["target_failure_rate"].description in page
    # and the shipped files' comments describe the keys a model leaves undescribed
    assert "room the fingers need beyond the object" in page


def test_scenario_schema_page_lists_the_top_level_keys():
    from scone_bt.scenario.model import json_schema

    page = docs_reference.scenario_schema_page()
    for key in json_schema()["properties"]:
        assert f"| `{key}` |" in page, key


@pytest.mark.parametrize("bad", ["build_parser_gone"])
def test_a_parser_that_is_gone_fails_the_build(bad: str):
    with pytest.raises(SystemExit, match="update COMMANDS"):
        docs_reference._parser_of("scone_bt.cli.models", (bad,))
    assert isinstance(docs_reference._parser_of("scone_bt.cli.models", ("_parser",)), argparse.ArgumentParser)


def test_the_scenario_page_names_every_key_rule_and_event_kind():
    """docs/scenarios.md is written by hand: a key, decision rule or event kind added in code must be added there."""
    from scone_bt.events import EVENT_TYPES
    from scone_bt.gate.types import DECISION_RULES
    from scone_bt.scenario import model

    page = (REPO / "docs" / "scenarios.md").read_text(encoding="utf-8")
    keys = [name for name in model.ScenarioFile.model_fields]
    keys += [f"world.{name}" for name in model.WorldSection.model_fields]
    keys += [f"robot.{name}" for name in ("profile", "calibration_offset")]
    # `world.*` in the page names the section
    missing = [k for k in keys if f"`{k}`" not in page and f"`{k}." not in page]
    # the robot's faults and the human's options are listed by name within one row each
    missing += [f"robot.{n}" for n in model.Fault.model_fields if f"{n}" not in page]
    missing += [f"human.{n}" for n in model.HumanSection.model_fields if f"`{n}`" not in page]
    missing += [f"rule {r}" for r in DECISION_RULES if f"`{r}`" not in page]
    missing += [f"event kind {k}" for k in EVENT_TYPES if f"`{k}`" not in page]
    assert not missing, f"docs/scenarios.md does not name: {missing}"
