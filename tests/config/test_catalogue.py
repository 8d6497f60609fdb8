"""The grocery catalogue: family files, validation errors, and a user's own product file."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.config import load_kitchen
from scone_bt.errors import ConfigError
from scone_bt.resources import data_dir
from scone_bt.world.visuals import DICTIONARY_SIZE, UNDRAWABLE_IDS

GOOD = "{name: %s, size: [0.05, 0.05, 0.1], mass: 0.2, rgba: [0.5, 0.5, 0.5, 1], marker_id: %d}"  # noqa: UP031


def _user_file(tmp_path: Path, body: str, head: str | None = None) -> Path:
    path = tmp_path / "mine.yaml"
    head = (
        head
        or "family: my jars\nsource: measured with a ruler\ndefaults: {shape: cylinder, material: glass, friction: 0.4}\n"
    )
    path.write_text(head + "products:\n" + body)
    return path


def _error(path: Path) -> str:
    with pytest.raises(ConfigError) as err:
        load_kitchen(catalogues=[path])
    message = str(err.value)
    assert "\n" not in message and str(path) in message
    return message


def test_shipped_catalogue_is_large_varied_and_dense(kitchen_cfg):
    cat = kitchen_cfg.catalogue
    assert len(cat) >= 200 and len(cat.families()) >= 12
    # Dense ids from 0, skipping the dictionary's one undrawable id, leaving the rest for users' own products.
    drawable = [i for i in range(DICTIONARY_SIZE) if i not in UNDRAWABLE_IDS]
    assert sorted(o.marker_id for o in cat.objects) == drawable[: len(cat)]
    assert len(drawable) - len(cat) >= 100
    names = [o.name for o in cat.objects]
    assert len(set(names)) == len(names)
    # Unlike products are distinct; only true synonyms are aliases.
    for name in ("cumin", "paprika", "cinnamon", "lime", "lemon", "maple syrup", "honey", "vegetable oil"):
        assert name in names, name
    assert "garbanzo beans" in cat.get("chickpeas").aliases
    assert "lime" not in cat.get("lemon").aliases and "cumin" not in cat.get("cinnamon").aliases
    # A family is handled alike and its products still vary in size and mass.
    cans = [o for o in cat.objects if o.family == "cans" and o.material == "metal"]
    assert len({o.shape for o in cans}) == 1 and len({o.mass for o in cans}) > 3


def test_every_family_file_says_where_its_figures_come_from():
    import yaml

    folder = Path(load_kitchen().source).parent / "catalogue"
    files = sorted(folder.glob("*.yaml"))
    assert len(files) >= 12
    for path in files:
        assert len(yaml.safe_load(path.read_text())["source"]) > 80, path


def test_user_file_adds_products_without_code(tmp_path, kitchen_cfg):
    path = _user_file(tmp_path, "  - " + GOOD % ("saffron syrup", 900) + "\n")
    cfg = load_kitchen(catalogues=[path])
    assert len(cfg.catalogue) == len(kitchen_cfg.catalogue) + 1
    mine = cfg.catalogue.get("saffron syrup")
    assert (mine.family, mine.shape, mine.material, mine.friction) == ("my jars", "cylinder", "glass", 0.4)
    assert cfg.catalogue.by_marker(900) is mine


def test_user_product_is_stocked_for_a_recipe(tmp_path):
    from scone_bt.recipes.recipe import recipe_from_record
    from scone_bt.stocking import stock_recipe

    path = _user_file(tmp_path, "  - " + GOOD % ("yuzu kosho", 900) + "\n")
    cfg = load_kitchen(catalogues=[path])
    recipe = recipe_from_record(
        {
            "ingredients": ["1 tsp yuzu kosho", "2 tbsp soy sauce"],
            "steps": ["Mix the yuzu kosho with soy sauce."],
        },
        "test",
    )
    assert stock_recipe(recipe, cfg.catalogue).needed == ("yuzu kosho", "soy sauce")
    assert stock_recipe(recipe, load_kitchen().catalogue).unstocked == ("1 tsp yuzu kosho",)


@pytest.mark.parametrize(
    ("product", "expected"),
    [
        (GOOD % ("salt", 900), "product 'salt': name: 'salt' is already product 'salt'"),
        (GOOD.replace("{name: %s,", "{name: %s, aliases: [cumin],") % ("my spice", 900), "aliases: 'cumin'"),
        (GOOD % ("my spice", 3), "marker_id: 3 is already product 'flour'"),
        (GOOD % ("my spice", 1000), "marker_id: 1000 is not a drawable marker (valid: 0-999 except 544"),
        (GOOD % ("my spice", 544), "marker_id: 544 is not a drawable marker"),
        (GOOD.replace("mass: 0.2", "mass: -0.2") % ("my spice", 900), "product 'my spice': mass:"),
        (GOOD.replace("mass: 0.2", "mass: 0") % ("my spice", 900), "mass: Input should be greater than 0"),
        (
            GOOD.replace("0.05, 0.05", "0.05, 0") % ("my spice", 900),
            "size[1]: Input should be greater than 0",
        ),
        (GOOD.replace("{name: %s,", "{name: %s, friction: -0.1,") % ("my spice", 900), "friction:"),
        (
            GOOD.replace("{name: %s,", "{name: %s, shape: sphere,") % ("my spice", 900),
            "shape: Input should be 'box' or 'cylinder'",
        ),
        (
            GOOD.replace("{name: %s,", "{name: %s, colour: red,") % ("my spice", 900),
            "unknown key 'colour'; valid: name, aliases",
        ),
        (
            GOOD.replace("mass: 0.2", "mass: heavy") % ("my spice", 900),
            "mass: Input should be a valid number",
        ),
        (
            GOOD.replace("marker_id: %d", "marker_id: '%d'") % ("my spice", 900),
            "marker_id: Input should be a valid integer",
        ),
        (
            GOOD.replace("size: [0.05, 0.05, 0.1]", "size: [0.05, 0.1]") % ("my spice", 900),
            "size: List should have at least 3 items",
        ),
        (
            GOOD.replace("size: [0.05, 0.05, 0.1]", "size: [10.0, 0.05, 0.1]") % ("my spice", 900),
            "product 'my spice': size[0]: Input should be less than or equal to 1 (got 10.0)",
        ),
        (
            GOOD.replace("mass: 0.2", "mass: 1000000000.0") % ("my spice", 900),
            "product 'my spice': mass: Input should be less than or equal to 50",
        ),
    ],
    ids=[
        "duplicate-name",
        "alias-is-other-name",
        "duplicate-marker",
        "marker-outside-dictionary",
        "marker-undrawable",
        "negative-mass",
        "zero-mass",
        "zero-size",
        "negative-friction",
        "unknown-shape",
        "unknown-key",
        "wrong-type",
        "marker-as-string",
        "short-size",
        "ten-metre-product",
        "billion-kilogram-product",
    ],
)
def test_bad_product_is_one_line_naming_file_product_and_field(tmp_path, product, expected):
    message = _error(_user_file(tmp_path, "  - " + product + "\n"))
    assert expected in message, message
    assert "my spice" in message or "salt" in message


def test_bad_family_header_is_one_line(tmp_path):
    path = _user_file(tmp_path, "  - " + GOOD % ("my spice", 900) + "\n", head="family: x\n")
    assert "source: missing (required)" in _error(path)
    path = _user_file(tmp_path, "  - [not, a, mapping]\n")
    assert "products[0]: expected a mapping" in _error(path)


def test_missing_user_file_is_one_line(tmp_path):
    assert "file not found" in _error(tmp_path / "nope.yaml")


def test_an_edited_family_file_is_read_again(tmp_path):
    import os

    from scone_bt.config.catalogue import load_catalogue

    path = _user_file(tmp_path, "  - " + GOOD % ("jar one", 990) + "\n")
    assert load_catalogue([path]).get("jar one").mass == 0.2
    assert load_catalogue([path]).get("jar one") is load_catalogue([path]).get("jar one")  # parsed once
    text = path.read_text()
    path.write_text(text.replace("mass: 0.2", "mass: 0.3"))  # the same size
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000))
    assert load_catalogue([path]).get("jar one").mass == 0.3
    path.write_text(text.replace("mass: 0.2", "mass: -1"))
    with pytest.raises(ConfigError, match="mass"):
        load_catalogue([path])


def test_a_kitchen_without_products_names_its_catalogue_key(tmp_path):
    text = (data_dir("perception") / "kitchen.yaml").read_text()
    assert "catalogue: [catalogue]" in text
    kitchen = tmp_path / "kitchen.yaml"
    kitchen.write_text(text.replace("catalogue: [catalogue]", "catalogue: []"))
    with pytest.raises(ConfigError) as err:
        load_kitchen(kitchen)
    assert str(err.value) == (
        f"{kitchen}: catalogue: lists no product files, so the kitchen has no products; give family files or "
        "folders of them (e.g. catalogue: [catalogue]) or --catalogue FILE"
    )
    (tmp_path / "empty").mkdir()
    kitchen.write_text(text.replace("catalogue: [catalogue]", "catalogue: [empty]"))
    with pytest.raises(ConfigError) as err:
        load_kitchen(kitchen)
    assert str(err.value) == (
        f"{tmp_path}: catalogue entry 'empty': the folder {tmp_path / 'empty'} holds no .yaml family files"
    )


def test_a_catalogue_entry_that_is_not_a_name_is_one_line_naming_the_entry(tmp_path):
    """`catalogue: [5]` was an internal TypeError from pathlib, naming no file."""
    text = (data_dir("perception") / "kitchen.yaml").read_text()
    kitchen = tmp_path / "kitchen.yaml"
    kitchen.write_text(text.replace("catalogue: [catalogue]", "catalogue: [5]"))
    with pytest.raises(ConfigError) as err:
        load_kitchen(kitchen)
    assert str(err.value) == f"{kitchen}: catalogue[0]: Input should be a valid string (got 5)"


def test_a_product_file_given_twice_says_so(tmp_path):
    """`--catalogue perception/catalogue/bags.yaml` said "'flour' is already product 'flour'"."""
    family = sorted((data_dir("perception") / "catalogue").glob("*.yaml"))[0]
    with pytest.raises(
        ConfigError, match=r"this product file is already in the catalogue \(as .*\); give it once"
    ):
        load_kitchen("kitchen", [str(family)])
