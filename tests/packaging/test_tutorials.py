"""The tutorials work as written: their files, saved where they say, run to the outcome they show.

Each test takes the tutorial's YAML blocks from its Markdown (so an edit to the page is what is tested), saves
them where the page tells the user to, and runs the scenario headless on PyBullet.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from scone_bt.scenario import runner

REPO = Path(__file__).resolve().parents[2]
TUTORIALS = REPO / "docs" / "tutorials"
BLOCK = re.compile(r"^```yaml\n(.*?)^```", re.MULTILINE | re.DOTALL)

pytestmark = pytest.mark.slow


def _yaml_blocks(page: str) -> list[str]:
    """The page's ```yaml blocks, in order."""
    return BLOCK.findall((TUTORIALS / page).read_text(encoding="utf-8"))


def _run(folder: Path) -> tuple[str, str]:
    """(verdict, why) of the one scenario in ``folder``."""
    (case,) = runner.load_cases([folder], None)
    result = runner.run_one(case, folder / "out", record_failures=False)
    return result.verdict, result.reason


def test_own_products_tutorial_cooks_the_users_recipe_from_its_scenario(tmp_path: Path) -> None:
    catalogue, recipe, scenario = _yaml_blocks("own-products.md")
    (tmp_path / "my-pantry.yaml").write_text(catalogue, encoding="utf-8")
    (tmp_path / "yuzu-noodles.yaml").write_text(recipe, encoding="utf-8")
    (tmp_path / "my-scenarios").mkdir()
    (tmp_path / "my-scenarios" / "yuzu-noodles.yaml").write_text(scenario, encoding="utf-8")
    # The library's copies are the tutorial's files (the page says so).
    library = REPO / "scenarios"
    assert yaml.safe_load(catalogue) == yaml.safe_load(
        (library / "catalogues" / "my-pantry.yaml").read_text(encoding="utf-8")
    )
    assert yaml.safe_load(recipe) == yaml.safe_load(
        (library / "recipes" / "yuzu-noodles.yaml").read_text(encoding="utf-8")
    )
    verdict, why = _run(tmp_path / "my-scenarios")
    assert verdict == "passed", why


def test_first_scenario_tutorial_passes_then_fails_on_purpose_as_shown(tmp_path: Path) -> None:
    (scenario,) = _yaml_blocks("first-scenario.md")
    folder = tmp_path / "runs" / "demo"
    folder.mkdir(parents=True)
    path = folder / "hidden-olive-oil.yaml"
    path.write_text(scenario, encoding="utf-8")
    assert _run(folder) == ("passed", "")
    # Step 3: one more expectation, which the robot breaks as the page shows.
    path.write_text(scenario + "  - {never_attempts: salt}\n", encoding="utf-8")
    verdict, why = _run(folder)
    assert verdict == "failed"
    assert "never_attempts: salt: the robot attempted 'salt'" in why
    page = (TUTORIALS / "first-scenario.md").read_text(encoding="utf-8")
    assert "failed: never_attempts: salt: the robot attempted 'salt'" in page
