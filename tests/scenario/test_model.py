"""The scenario loader: one-line errors naming the file, the key and the valid choices; sweeps; the schema."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from scone_bt.errors import ConfigError
from scone_bt.scenario.model import json_schema, load_scenario, load_scenarios

REPO = Path(__file__).resolve().parents[2]
LIBRARY = REPO / "scenarios"


def _write(tmp_path: Path, text: str, name: str = "case.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _error(tmp_path: Path, text: str) -> str:
    path = _write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    return message


BASE = "description: d\nexpect:\n  - {completes: true}\n"


def test_unknown_top_level_key_names_the_valid_keys(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "wrld: {seed: 1}\n")
    assert "unknown key 'wrld'" in msg
    assert (
        "valid: description, name, expected, reason, tags, world, robot, human, events, expect, sweep" in msg
    )


def test_unknown_key_inside_an_expectation_names_its_keys(tmp_path: Path) -> None:
    msg = _error(tmp_path, "description: d\nexpect:\n  - {never_attempts: salt, colour: red}\n")
    assert msg.endswith("expect[0]: unknown key 'colour'; valid: name, never_attempts")


def test_bad_product_lists_the_products_of_the_episode(tmp_path: Path) -> None:
    msg = _error(tmp_path, "description: d\nexpect:\n  - {never_attempts: unicorn}\n")
    assert "expect[0].never_attempts: 'unicorn' is not a product of the catalogue; valid: " in msg
    assert "olive oil" in msg and "salt" in msg


def test_a_failure_bound_of_an_unknown_product_is_refused(tmp_path: Path) -> None:
    """`{max_failures: 1, object: unicorn}` passed `check`: it counted no failures, so it always held."""
    msg = _error(tmp_path, "description: d\nexpect:\n  - {max_failures: 0, object: unicorn}\n")
    assert "expect[0].object: 'unicorn' is not a product of the catalogue; valid: " in msg


def test_product_of_the_catalogue_not_in_this_episode(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "world: {hidden_markers: [lard]}\n")
    assert "world.hidden_markers[0]: 'lard' is not stocked in this episode; valid: " in msg


def test_too_many_distractors_names_the_scenario_key_not_the_command_line_flag(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "world: {distractors: 40}\n")
    assert ": world: distractors 40: " in msg and "available for this recipe and shelf" in msg, msg
    assert "--distractors" not in msg


def test_time_in_the_past(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "events:\n  - {at: -1, remove: salt}\n")
    assert msg.endswith("events[0]: at: -1.0 s is in the past (the episode starts at 0 s)")


def test_time_after_the_end(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "world: {max_ticks: 100}\nevents:\n  - {at: 50, remove: salt}\n")
    assert "events[0].at: 50 s is after the episode's end (10 s: max_ticks × tick_period)" in msg


def test_unknown_event_lists_the_actions(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "events:\n  - {at: 1, explode: salt}\n")
    assert "events[0]: an event needs exactly one of: move, swap, remove, to_table" in msg
    assert "(got keys: at, explode)" in msg


def test_unknown_expectation_lists_the_kinds(tmp_path: Path) -> None:
    msg = _error(tmp_path, "description: d\nexpect:\n  - {succeeds: true}\n")
    assert "expect[0]: an expectation needs exactly one of: asks_before_attempt, never_attempts" in msg


def test_unreachable_slot(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "world: {place: [{product: salt, slot: front/4/0}]}\n")
    assert msg.endswith("world.place[0].slot: unit 'front' has tiers 0-2 (got 4)")
    msg = _error(tmp_path, BASE + "world: {place: [{product: salt, slot: top/0/0}]}\n")
    assert "unknown shelf unit 'top'; valid: front, left, back" in msg


def test_unknown_camera_and_unknown_event_kind(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "events:\n  - {at: 1, cover_camera: ceiling}\n")
    assert (
        "events[0].cover_camera: unknown camera 'ceiling'; valid: shelf_front, shelf_left, shelf_back, table"
        in msg
    )
    msg = _error(tmp_path, BASE + "events:\n  - {when: {kind: explosion}, remove: salt}\n")
    assert "events[0].when.kind: Input should be 'decision'" in msg


def test_expected_fail_needs_a_reason_and_parameters_are_checked(tmp_path: Path) -> None:
    assert "expected: fail needs a 'reason'" in _error(tmp_path, BASE + "expected: fail\n")
    msg = _error(tmp_path, BASE + "world: {parameters: {gate: bogus}}\n")
    assert msg.endswith("world.parameters: gate: Input should be 'budget' or 'paper' (got 'bogus')")
    # names the registries cannot build, as a tree file's are (they passed `check` and failed when run)
    msg = _error(tmp_path, BASE + "world: {parameters: {embedder: nosuch}}\n")
    assert (
        "world.parameters: embedder: unknown embedder 'nosuch'; valid: glove, minilm, mpnet, mpnet-ft" in msg
    )
    msg = _error(tmp_path, BASE + "world: {parameters: {estimator: nosuch}}\n")
    assert "world.parameters: estimator: unknown estimator 'nosuch'; valid: conformal" in msg


def test_unknown_profile_and_recipe(tmp_path: Path) -> None:
    assert "unknown profile 'p99'; valid: p00_nominal" in _error(tmp_path, BASE + "robot: {profile: p99}\n")
    assert "world: unknown example recipe 'nope'" in _error(
        tmp_path, BASE + "world: {recipe: 'example:nope'}\n"
    )


def test_a_sweep_gives_one_case_per_value(tmp_path: Path) -> None:
    path = _write(tmp_path, BASE + "sweep:\n  robot.gripper_force: [5, 20, 70]\n  world.seed: [0, 1]\n")
    cases = load_scenario(path)
    assert [c.name for c in cases] == [
        f"case[robot.gripper_force={f},world.seed={s}]" for f in (5, 20, 70) for s in (0, 1)
    ]
    assert [(c.spec.robot.gripper_force, c.spec.world.seed) for c in cases] == [
        (f, s) for f in (5.0, 20.0, 70.0) for s in (0, 1)
    ]


def test_a_range_sweep_and_a_bad_value_names_the_case(tmp_path: Path) -> None:
    path = _write(tmp_path, BASE + "sweep:\n  human.patience_s: {start: 2, stop: 10, step: 4}\n")
    assert [c.spec.human.patience_s for c in load_scenario(path)] == [2.0, 6.0, 10.0]
    msg = _error(tmp_path, BASE + "sweep:\n  robot.gripper_force: [20, -1]\n")
    assert "[robot.gripper_force=-1]: robot.gripper_force: Input should be greater than 0" in msg


@pytest.mark.parametrize(
    ("sweep", "expected"),
    [
        # each took forever or overflowed before (10^12 values; (1e308 - -1e308) / 1e-300 is infinite)
        ("{start: 0.0, stop: 1000000000000.0, step: 1.0}", "holds more than 50 values; give a larger step"),
        ("{start: -1.0e+308, stop: 1.0e+308, step: 1.0e-300}", "holds more than 50 values"),
    ],
)
def test_a_range_sweep_is_bounded_and_says_so(tmp_path: Path, sweep: str, expected: str) -> None:
    msg = _error(tmp_path, BASE + f"sweep:\n  human.patience_s: {sweep}\n")
    assert "sweep.human.patience_s: the range from" in msg and expected in msg


def test_a_sweep_error_names_the_file_s_keys_not_the_union_s_tags(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "sweep:\n  world.seed: {start: 1, stop: 5, step: 0}\n")
    assert msg.endswith(
        "sweep.world.seed.step: Input should be greater than 0 (got 0)"
    )  # was seed.range.step


def test_a_sweep_of_too_many_combinations_is_refused(tmp_path: Path) -> None:
    values = list(range(1, 31))
    msg = _error(tmp_path, BASE + f"sweep:\n  robot.gripper_force: {values}\n  world.seed: {values}\n")
    assert "sweep: 30 × 30 = 900 cases, more than 500" in msg


def test_the_library_loads_and_every_scenario_says_what_it_pins() -> None:
    cases = load_scenarios([LIBRARY])
    files = {c.path for c in cases}
    assert len(files) >= 25
    for case in cases:
        assert len(case.spec.description.split()) >= 6, case.name
        if case.spec.expected == "fail":
            assert case.spec.reason


def test_the_committed_schema_is_the_models_and_accepts_the_library() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    import yaml

    committed = json.loads((LIBRARY / "scenario.schema.json").read_text(encoding="utf-8"))
    assert committed == json_schema(), "run: scone-scenario schema scenarios/scenario.schema.json"
    validator = jsonschema.Draft202012Validator(committed)
    for path in sorted(LIBRARY.glob("*.yaml")):
        validator.validate(yaml.safe_load(path.read_text(encoding="utf-8")))
    with pytest.raises(jsonschema.ValidationError):
        validator.validate({"description": "d", "expect": [{"completes": True}], "colour": 1})


def test_neighbours_stand_beside_the_pinned_slot_nearest_first() -> None:
    from scone_bt.scenario.model import Placement

    pl = Placement(product="parmesan", slot="left/1/1", neighbours=["a", "b", "c"])
    assert pl.neighbour_slots(4) == [("a", "left/1/2"), ("b", "left/1/0"), ("c", "left/1/3")]
    assert pl.neighbour_slots(2) == [("a", "left/1/0")]  # no slot 2: the free one on the other side


def test_neighbours_that_do_not_fit_on_the_tier(tmp_path: Path) -> None:
    text = (
        BASE
        + "world:\n  place: [{product: salt, slot: left/2/0, neighbours: [garlic, parmesan, spaghetti]}]\n"
    )
    msg = _error(tmp_path, text)
    assert msg.endswith(
        "world.place[0].neighbours: tier left/2 has 3 slots, no room for 3 neighbours beside slot left/2/0"
    )


def test_swap_needs_two_stocked_products(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "events:\n  - {at: 1, swap: {product: salt, with: lard}}\n")
    assert "events[0].swap.with: 'lard' is not stocked in this episode; valid: " in msg


def test_faults_are_range_checked(tmp_path: Path) -> None:
    msg = _error(tmp_path, BASE + "robot: {calibration_offset: [0.5, 0, 0]}\n")
    assert "robot.calibration_offset[0]: Input should be less than or equal to 0.1" in msg
    msg = _error(tmp_path, BASE + "human: {help_answer: maybe}\n")
    assert "human.help_answer: Input should be 'fetch' or 'decline'" in msg


def test_a_count_naming_no_product_or_stage_is_an_error_not_a_vacuous_pass(tmp_path: Path) -> None:
    msg = _error(tmp_path, "description: d\nexpect:\n  - {count: {kind: outcome, object: sallt}, max: 0}\n")
    assert msg.endswith(
        "expect[0].count.object: 'sallt' is not a product of the catalogue (did you mean 'salt'?)"
    )
    msg = _error(tmp_path, "description: d\nexpect:\n  - {count: {kind: outcome, stage: grsp}, max: 0}\n")
    assert msg.endswith(
        "expect[0].count.stage: unknown failure stage 'grsp'; valid: perception, ik, planning, grasp, transit, "
        "collision, place, timeout, cancelled, probe"
    )
    msg = _error(tmp_path, BASE + "events:\n  - {when: {kind: outcome, stage: grsp}, remove: salt}\n")
    assert "events[0].when.stage: unknown failure stage 'grsp'" in msg
    msg = _error(
        tmp_path, "description: d\nexpect:\n  - {count: {kind: decision, rule: failur-limit}, max: 0}\n"
    )
    assert msg.endswith(
        "expect[0].count.rule: unknown decision rule 'failur-limit'; valid: failure-limit, infeasible, missing, "
        "declined, too-wide, self-confidence-off, probe, or '' (κ̂ against the threshold)"
    )
    msg = _error(tmp_path, "description: d\nexpect:\n  - {count: {kind: decision}, min: 3, max: 1}\n")
    assert msg.endswith("expect[0]: min 3 is above max 1: no count passes")
    # A product of the catalogue that this episode does not stock may be counted (an ask for a missing item).
    load_scenario(
        _write(tmp_path, "description: d\nexpect:\n  - {count: {kind: decision, object: lard}, max: 0}\n")
    )


def test_two_pins_on_one_slot_are_an_error(tmp_path: Path) -> None:
    msg = _error(
        tmp_path,
        BASE + "world:\n  place: [{product: olive oil, slot: back/0/2}, {product: salt, slot: back/0/2}]\n",
    )
    assert msg.endswith(
        "world.place[1].slot: back/0/2 is already world.place[0]'s (olive oil); give each product its own slot"
    )


def test_a_value_where_a_section_belongs_names_its_keys_not_a_class(tmp_path: Path) -> None:
    """pydantic said "Input should be a valid dictionary or instance of WorldSection"."""
    msg = _error(tmp_path, "description: d\nworld: 5\nexpect: [{completes: true}]\n")
    assert "world: must be a mapping of keys to values (robot, arm, kitchen" in msg and msg.endswith(
        "(got 5)"
    )
    assert "instance of" not in msg


def test_a_missing_recipe_file_names_where_it_was_looked_for(tmp_path: Path) -> None:
    """It said "recipe file not found: recipes/nope.yaml", relative to nothing said."""
    msg = _error(
        tmp_path, "description: d\nworld: {recipe: recipes/nope.yaml}\nexpect: [{completes: true}]\n"
    )
    assert msg.endswith(f"recipe file not found: {tmp_path / 'recipes' / 'nope.yaml'}")
