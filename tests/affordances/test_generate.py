from scone_bt.affordances import action_text, generate_affordances
from scone_bt.perception.types import Detection


def det(name, pos, conf=0.9):
    return Detection(name, 0, pos, 0.0, conf, (0, 0, 1, 1))


def test_only_shelf_objects_become_affordances(kitchen_cfg):
    scene = kitchen_cfg.scene
    dets = [det("salt", (0.5, 0.4, 0.1)), det("milk", (0.47, -0.43, 0.1)), det("salt", (0.5, 0.41, 0.1), 0.5)]
    affs = generate_affordances(dets, scene)
    assert [a.text for a in affs] == [action_text("salt")] == ["Put salt on table"]
    assert affs[0].detection.confidence == 0.9
