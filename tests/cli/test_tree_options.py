"""Tree settings are declared once, in `TreeParameters`: scone-run's options and `BehaviourOptions` follow it."""

from __future__ import annotations

import dataclasses
import typing

import pytest

import scone_bt.behaviours.options as options_module
from scone_bt.behaviours import BehaviourOptions
from scone_bt.cli.run import build_parser, main, options_from_args
from scone_bt.cli.tree_options import dest_of, flag_of, option_fields
from scone_bt.config.tree_parameters import PARAMETER_NAMES, GateName, ProbeParameters, TreeParameters
from scone_bt.errors import SconeError


def test_every_tree_parameter_is_a_scone_run_option_with_its_description_as_help() -> None:
    actions = {a.dest: a for a in build_parser()._actions}
    leaves = {
        (name, *sub)
        for name, field in TreeParameters.model_fields.items()
        for sub in (
            [(s,) for s in ProbeParameters.model_fields] if field.annotation is ProbeParameters else [()]
        )
    }
    assert {path for path, _ in option_fields()} == leaves  # a nested section: one option per field of it
    for path, field in option_fields():
        action = actions[dest_of(path)]
        assert flag_of(path) in action.option_strings
        assert action.default is None  # left out: the tree file's value
        assert field.description and field.description in (action.help or "")
    assert actions["gate"].choices == typing.get_args(GateName)
    assert "--probe-lift-m" in actions["probe_lift_m"].option_strings
    assert "--no-probe-enabled" in actions["probe_enabled"].option_strings


def test_behaviour_options_hold_the_tree_parameters_with_their_types() -> None:
    names = {"GateName": GateName, "ProbeParameters": ProbeParameters}
    hints = typing.get_type_hints(BehaviourOptions, {**vars(options_module), **names})
    defaults = {f.name: f.default for f in dataclasses.fields(BehaviourOptions)}
    for name in PARAMETER_NAMES:
        assert defaults[name] is None, name
        assert hints[name] == (TreeParameters.model_fields[name].annotation | None), name


def test_options_reach_the_behaviour_options_unmapped() -> None:
    argv = [
        "--no-recipe-aware",
        "--clarify-margin",
        "0.1",
        "--max-failures-per-action",
        "2",
        "--gate",
        "paper",
    ]
    behaviour = options_from_args(build_parser().parse_args(argv)).behaviour
    assert (behaviour.recipe_aware, behaviour.clarify_margin, behaviour.max_failures_per_action) == (
        False,
        0.1,
        2,
    )
    assert behaviour.gate == "paper" and behaviour.estimator is None  # not given: the tree file's


def test_a_probe_option_overrides_only_its_key_of_the_tree_files_section() -> None:
    argv = ["--probe-below", "0.1", "--probe-enabled"]
    behaviour = options_from_args(build_parser().parse_args(argv)).behaviour
    resolved = behaviour.resolve({"probe": {"hold_s": 1.0, "below": 0.4}})
    assert resolved.probe == ProbeParameters(enabled=True, below=0.1, hold_s=1.0)
    assert BehaviourOptions().resolve({"probe": {"hold_s": 1.0}}).probe == ProbeParameters(hold_s=1.0)


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--clarify-margin", "2"], "--clarify-margin 2.0: must be a number in [0, 1]"),
        (["--max-failures-per-action", "0"], "--max-failures-per-action 0: must be a number in [1, 1000]"),
        (["--target-failure-rate", "1"], "--target-failure-rate 1.0: must be a number in (0, 1)"),
        (["--confidence-threshold", "nan"], "--confidence-threshold nan: must be a number in [0, 1]"),
        (["--probe-lift-m", "0.2"], "--probe-lift-m 0.2: must be a number in [0.005, 0.05]"),
    ],
)
def test_a_bad_setting_is_one_line_naming_the_option_and_its_range(argv, line, capsys) -> None:
    assert main(argv) == 2
    assert capsys.readouterr().err == f"scone-run: error: {line}\n"


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--gate", "paper", "--probe-enabled"], "--probe-enabled has no effect with the paper's gate"),
        (
            ["--gate", "paper", "--exploration-credit"],
            "--exploration-credit has no effect with the paper's gate",
        ),
        (
            ["--gate", "paper", "--target-failure-rate", "0.1"],
            "--target-failure-rate has no effect with the paper",
        ),
        (["--confidence-threshold", "0.9"], "--confidence-threshold has no effect with the budget gate"),
        (
            ["--no-self-confidence", "--probe-lift-m", "0.02"],
            "--probe-lift-m has no effect with --no-self-confidence",
        ),
        (["--no-self-confidence", "--gate", "paper"], "--gate has no effect with --no-self-confidence"),
    ],
)
def test_an_option_this_run_would_not_read_is_refused(argv, line, capsys) -> None:
    """One meaning per flag: `--gate paper --probe-enabled` ran the paper's gate and never probed, without a word."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-run: error: {line}") and err.count("\n") == 1


def test_the_options_of_the_gate_in_use_are_taken(capsys) -> None:
    behaviour = options_from_args(
        build_parser().parse_args(["--gate", "paper", "--confidence-threshold", "0.7"])
    )
    assert behaviour.behaviour.confidence_threshold == 0.7
    budget = options_from_args(
        build_parser().parse_args(["--probe-enabled", "--exploration-credit"])
    ).behaviour
    assert budget.probe is not None and budget.exploration_credit is True


def test_the_paper_gate_runs_over_a_tree_whose_budget_switches_are_on(tmp_path) -> None:
    """The shipped tree turns the heft probe and the strict promise on: `--gate paper` over it, or a tree file
    with gate: paper, runs the paper's gate, which reads neither (as the budget gate does not read
    confidence_threshold; scenarios/paper-gate-self-confidence.yaml checks that it never probes); the switches
    given on the command line with the paper's gate are still refused."""
    from scone_bt.resources import data_dir
    from scone_bt.tree import load_tree_spec

    shipped = TreeParameters.model_validate(load_tree_spec("assistive_cooking").parameters)
    assert shipped.probe.enabled and shipped.exploration_credit  # the premise
    paper = options_from_args(build_parser().parse_args(["--gate", "paper"])).behaviour
    assert paper.gate == "paper"
    text = (data_dir("trees") / "assistive_cooking.yaml").read_text(encoding="utf-8")
    tree = tmp_path / "tree.yaml"
    tree.write_text(text.replace("  gate: budget", "  gate: paper"), encoding="utf-8")
    assert options_from_args(build_parser().parse_args(["--tree", str(tree)])).behaviour.gate is None
    assert TreeParameters(gate="paper", probe=ProbeParameters(enabled=True), exploration_credit=True)
    for flag in ("--probe-enabled", "--no-exploration-credit", "--no-probe-enabled"):  # named as given
        with pytest.raises(SconeError, match=f"^{flag} has no effect with the paper's gate"):
            options_from_args(build_parser().parse_args(["--gate", "paper", flag]))


def test_a_probe_setting_while_the_probe_is_off_is_refused(capsys) -> None:
    """`--probe-below 0.5` with the probe off changed nothing and said nothing."""
    assert main(["--no-probe-enabled", "--probe-below", "0.5"]) == 2
    err = capsys.readouterr().err
    assert "--probe-below has no effect while the probe is off: give --probe-enabled too" in err
    # the probe is on in the shipped tree
    behaviour = options_from_args(build_parser().parse_args(["--probe-below", "0.5"]))
    assert behaviour.behaviour.resolve({}).probe == ProbeParameters(enabled=True, below=0.5)
