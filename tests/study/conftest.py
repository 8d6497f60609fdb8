"""Fixtures of the study tests: a kitchen with a recipe's objects and a headless Chromium page."""

from __future__ import annotations

import importlib.util
import shutil
import sys

import pytest

# The rootdir conftest puts tests/ on sys.path, so the folder tests/tree shadows the optional dm-tree package that
# ArviZ probes for with `import tree`; make that probe fail as it does outside pytest.
_spec = importlib.util.find_spec("tree")
if _spec is not None and _spec.origin in (None, "namespace"):
    sys.modules["tree"] = None  # type: ignore[assignment]

CHROMIUM = "/usr/bin/chromium"


@pytest.fixture
def stocked(kitchen, kitchen_cfg, rng):
    """The tomato-pasta recipe with its objects on the shelf."""
    from scone_bt.recipes import load_recipe
    from scone_bt.stocking import stock_recipe

    recipe = stock_recipe(load_recipe("example:tomato-pasta"), kitchen_cfg.catalogue)
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in recipe.needed], rng)
    return recipe


@pytest.fixture
def browser_page():
    """A Playwright page in Debian's headless Chromium (no browser download), or a skip saying what is missing."""
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"{CHROMIUM} not installed: apt-get install -y chromium")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (Python) not installed")
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=CHROMIUM,
            headless=True,
            args=[
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
            ],
        )
        context = browser.new_context(viewport={"width": 800, "height": 1280}, is_mobile=False)
        page = context.new_page()
        page.set_default_timeout(15_000)
        yield page
        context.close()
        browser.close()
