from pathlib import Path

import pytest

from scone_bt.config import load_kitchen, load_robot
from scone_bt.errors import ConfigError, UnknownNameError


def test_catalogue_has_enough_distinct_objects(kitchen_cfg):
    cat = kitchen_cfg.catalogue
    assert len(cat) >= 21
    assert len(set(cat.names())) == len(cat)
    for obj in cat.objects:
        assert obj.mass > 0 and obj.friction > 0 and all(s > 0 for s in obj.size)
        assert cat.by_marker(obj.marker_id) is obj


def test_unknown_object_names_the_valid_ones(kitchen_cfg):
    with pytest.raises(UnknownNameError) as err:
        kitchen_cfg.catalogue.get("unicorn")
    assert "unicorn" in str(err.value) and "salt" in str(err.value)
    assert "\n" not in str(err.value)


def test_robot_config_has_consistent_dimensions(robot_cfg):
    assert robot_cfg.dof == len(robot_cfg.home) == len(robot_cfg.limits.velocity)
    assert robot_cfg.urdf.is_file()


def test_unknown_robot_lists_available():
    with pytest.raises(UnknownNameError, match="panda"):
        load_robot("no_such_robot")


def test_malformed_yaml_is_one_line_error(tmp_path: Path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("scene: [unclosed\n")
    with pytest.raises(ConfigError) as err:
        load_kitchen(bad)
    assert str(bad) in str(err.value) and "\n" not in str(err.value)


def test_missing_urdf_is_reported(tmp_path: Path):
    text = (
        (Path(load_robot().source))
        .read_text()
        .replace("pybullet_data://franka_panda/panda.urdf", "missing.urdf")
    )
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match="URDF not found"):
        load_robot(path)


def test_bad_object_shape_names_valid_shapes(tmp_path: Path, kitchen_cfg):
    path = tmp_path / "mine.yaml"
    path.write_text(
        "family: mine\nsource: test\nproducts:\n  - {name: orb, shape: sphere, size: [0.05, 0.05, 0.05],"
        " mass: 0.1, friction: 0.5, material: glass, rgba: [1, 1, 1, 1], marker_id: 999}\n"
    )
    with pytest.raises(ConfigError, match="'box' or 'cylinder'"):
        load_kitchen(catalogues=[path])


def test_camera_shapes_lists_the_valid_choices(tmp_path: Path):
    text = (
        Path(load_robot().source).read_text().replace("camera_shapes: collision", "camera_shapes: wireframe")
    )
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_robot(path)
    message = str(err.value)
    assert (
        "camera_shapes" in message and "visual" in message and "collision" in message and "\n" not in message
    )


def test_a_catalogue_entry_that_is_no_file_or_folder_names_the_kitchen_key_and_the_folders(tmp_path: Path):
    from scone_bt.resources import data_dir

    text = (data_dir("perception") / "kitchen.yaml").read_text()
    kitchen = tmp_path / "k.yaml"
    kitchen.write_text(text.replace("catalogue: [catalogue]", "catalogue: [catalogue, nosuchdir]"))
    with pytest.raises(ConfigError) as err:
        load_kitchen(kitchen)
    msg = str(err.value)
    assert msg.startswith(f"{kitchen}: catalogue[1]: 'nosuchdir' is neither a file nor a folder")
    assert msg.endswith("give family files (.yaml, .json) or folders of them (valid folders: catalogue)")
    assert "\n" not in msg
