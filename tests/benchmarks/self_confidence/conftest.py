"""Fixtures of the self-confidence evaluation tests: small datasets in the generator's CSV contract (seeded)."""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.dataset import COLUMNS

# Glass bottles fail; cans succeed; boxes and bags succeed unless crowded (clearance < 3 cm).
FAMILIES = {
    "glass bottles": ["olive oil", "vinegar", "soy sauce", "sesame oil", "fish sauce", "maple syrup"],
    "cans": ["canned tomatoes", "chickpeas", "coconut milk", "black beans", "sweetcorn", "tuna"],
    "boxes": ["spaghetti", "rice", "couscous", "oats", "cornflakes", "lasagne sheets"],
    "bags": ["flour", "sugar", "lentils", "quinoa", "polenta", "breadcrumbs"],
}


def outcome(family: str, clearance: float) -> bool:
    """The synthetic robot's rule."""
    if family == "glass bottles":
        return False
    if family in ("bags", "boxes"):
        return clearance >= 0.03
    return True


def write_datasets(directory: Path, n_datasets: int = 2, rows: int = 40, context: bool = True) -> Path:
    """`n_datasets` CSVs of `rows` executions each; products drawn uniformly from FAMILIES."""
    directory.mkdir(parents=True, exist_ok=True)
    products = [(p, f) for f, ps in FAMILIES.items() for p in ps]
    for d in range(n_datasets):
        rng = np.random.default_rng(100 + d)
        with (directory / f"p{d:02d}_robot.csv").open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for i in range(rows):
                name, family = products[int(rng.integers(len(products)))]
                clearance = float(rng.uniform(0.0, 0.08))
                ok = outcome(family, clearance)
                detected = bool(rng.random() < 0.9)
                ctx = [
                    "0",
                    str(int(rng.integers(3))),
                    str(int(rng.integers(12))),
                    f"{clearance:.4f}",
                    str(int(rng.integers(3))),
                    "1" if detected else "0",
                    "0.07" if detected else "",
                    "0.2" if detected else "",
                ]
                if not context:
                    ctx = [""] * len(ctx)
                w.writerow(
                    [i, f"Put {name} on table", name, family, "success" if ok else "failure"]
                    + ["" if ok else "grasp", 1000 + i, "synthetic"]
                    + ctx
                    + ["0.07", "0.2", "0.5", "glass" if family == "glass bottles" else "other"]
                )
    return directory


@pytest.fixture
def sc_data(tmp_path: Path) -> Callable[..., Path]:
    """write_datasets into a fresh folder under tmp_path: sc_data(n_datasets=2, rows=40, context=True)."""
    count = iter(range(1000))

    def make(**kwargs: object) -> Path:
        return write_datasets(tmp_path / f"sc{next(count)}", **kwargs)  # type: ignore[arg-type]

    return make


@pytest.fixture
def user_catalogue(kitchen_cfg) -> Callable[[Path], Path]:
    """user_catalogue(folder): a user's product file of three tins ("my tins") with free marker ids."""

    def make(tmp_path: Path) -> Path:
        used = {o.marker_id for o in kitchen_cfg.catalogue.objects}
        free = [i for i in range(1000) if i not in used and i != 544][:3]
        assert len(free) == 3, "the test needs three free marker ids"
        path = tmp_path / "my_products.yaml"
        path.write_text(
            "family: my tins\n"
            "source: measured in my own kitchen\n"
            "defaults: {shape: cylinder, material: metal, friction: 0.35}\n"
            "products:\n"
            f"  - {{name: smoked paprika tin, size: [0.06, 0.06, 0.08], mass: 0.12, rgba: [0.8, 0.2, 0.1, 1], marker_id: {free[0]}}}\n"
            f"  - {{name: saffron tin, size: [0.05, 0.05, 0.06], mass: 0.05, rgba: [0.9, 0.7, 0.1, 1], marker_id: {free[1]}}}\n"
            f"  - {{name: matcha tin, size: [0.07, 0.07, 0.09], mass: 0.15, rgba: [0.3, 0.6, 0.2, 1], marker_id: {free[2]}}}\n"
        )
        return path

    return make
