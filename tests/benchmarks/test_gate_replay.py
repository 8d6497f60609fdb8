"""``scone-bench gate``'s online replay: an asked action adds no label (censoring), wide attempts after a stream's
first wide failure are counted, a seeded replay repeats exactly, and the report carries the keys issue 26 names."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import scone_bt.confidence
from scone_bt.benchmarks.gate import TARGETS
from scone_bt.benchmarks.replay import StreamResult, replay_stream
from scone_bt.benchmarks.replay_rates import pooled_rates
from scone_bt.cli.bench import main
from scone_bt.gate.budget import BudgetOptions

OPENING_M = 0.08
REPO = Path(__file__).resolve().parents[2]


class _Scripted:
    """κ̂ whose prediction for a row is the row's first value; the second value is the row's index in the stream,
    so the test sees exactly which decisions were learnt from. No ``explores``: the paper gate acts iff p ≥ 0.5."""

    def __init__(self) -> None:
        self.learnt: list[tuple[int, bool]] = []

    @property
    def n_observations(self) -> int:
        return len(self.learnt)

    def predict(self, X: np.ndarray) -> np.ndarray:
        return np.asarray(X, dtype=float)[:, 0]

    def update(self, x: np.ndarray, success: bool) -> None:
        self.learnt.append((int(x[1]), bool(success)))


def _use(monkeypatch: pytest.MonkeyPatch, estimator: object) -> None:
    monkeypatch.setattr(scone_bt.confidence, "make_estimator", lambda name, seed=0, **options: estimator)


def _context(widths: list[float]) -> np.ndarray:
    """(n, 6) context rows in CONTEXT_FIELDS order with these perceived widths."""
    n = len(widths)
    return np.column_stack([np.ones(n), np.full(n, 0.1), np.ones(n), np.ones(n), widths, np.full(n, 0.1)])


def test_an_asked_action_adds_no_label(monkeypatch: pytest.MonkeyPatch) -> None:
    scores = np.array([0.9, 0.2, 0.7, 0.4, 0.1, 0.6, 0.3, 0.8])
    success = np.array([True, True, False, False, True, True, False, True])
    vectors = np.column_stack([scores, np.arange(len(scores))]).astype(np.float32)
    kappa = _Scripted()
    _use(monkeypatch, kappa)
    out = replay_stream(
        vectors,
        _context([0.05] * 8),
        success,
        [f"p{i}" for i in range(8)],
        "x",
        "paper",
        0.5,
        0,
        0,
        OPENING_M,
    )
    acted = [t for t in range(8) if scores[t] >= 0.5]
    assert kappa.learnt == [
        (t, bool(success[t])) for t in acted
    ]  # the attempts' labels, in order, nothing else
    assert (out.all_decisions, out.all_attempts, out.all_asked) == (8, len(acted), 8 - len(acted))
    assert (out.asked_ok, out.asked_fail, out.failures) == (2, 2, 1)
    rates = pooled_rates([out])
    assert rates["help_rate"] == 0.5 and rates["over_ask_rate"] == 0.25 and rates["over_step_rate"] == 0.125
    assert rates["attempt_failure_rate"] == 0.25 and rates["success_rate"] == 0.375
    # 5 of the 8 would succeed: at a failure rate of 0.25 a clairvoyant attempts 5 / 0.75 and asks for the rest
    assert rates["help_rate_floor"] == round(1 - (5 / 0.75) / 8, 4)
    assert rates["help_rate_floor_per_stream"] == [rates["help_rate_floor"]]  # one stream: its own floor
    # a clairvoyant that never fails attempts the 5 and asks for the other 3
    assert rates["help_rate_floor_without_failures"] == round(3 / 8, 4)
    again = pooled_rates([out, out])  # two streams: each at its own rate, here the same
    assert again["help_rate_floor_per_stream"] == [rates["help_rate_floor"]] * 2


def test_the_help_floor_is_a_clairvoyants() -> None:
    from scone_bt.benchmarks.replay_rates import help_floor

    assert help_floor(79, 100, 0.15) == 0.0706  # the nominal robot's 79 successes in 100
    assert help_floor(95, 100, 0.15) == 0.0  # more than enough successes: attempt everything
    assert help_floor(40, 100, 0.0) == 0.6  # no failure allowed: only the 40 successes
    assert help_floor(40, 0, 0.1) is None and help_floor(40, 100, None) is None


def _physical_stream(n: int = 30, seed: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """Ten products (one embedding each) picked n times; the wide ones mostly fail."""
    rng = np.random.default_rng(seed)
    table = rng.normal(size=(10, 8)).astype(np.float32)
    widths = np.linspace(0.03, 0.12, 10)
    pick = rng.integers(0, 10, n)
    context = _context(list(widths[pick]))
    success = (widths[pick] < 0.075) ^ (rng.random(n) < 0.1)
    return table[pick], context, success, [f"product {i}" for i in pick]


@pytest.mark.parametrize("gate", ["budget", "fixed", "conformal"])
def test_the_real_estimator_learns_only_from_attempts(monkeypatch: pytest.MonkeyPatch, gate: str) -> None:
    made = []
    real = scone_bt.confidence.make_estimator

    def spy(name: str, seed: int = 0, **options: float):
        made.append(real(name, seed=seed, **options))
        return made[-1]

    monkeypatch.setattr(scone_bt.confidence, "make_estimator", spy)
    vectors, context, success, products = _physical_stream()
    estimator = "conformal" if gate == "conformal" else "physical"
    out = replay_stream(vectors, context, success, products, estimator, gate, 0.1, 0, 5, OPENING_M)
    (kappa,) = made
    assert out.all_asked > 0 and out.all_attempts > 0
    assert kappa.n_observations == out.all_attempts < out.all_decisions == len(success)


def test_wide_attempts_after_the_first_wide_failure_are_counted(monkeypatch: pytest.MonkeyPatch) -> None:
    widths = [0.10, 0.03, 0.10, 0.03, 0.11, 0.12, 0.05, 0.08]  # 0.08: the opening itself is not wider than it
    success = np.array([True, True, False, True, True, False, True, True])
    vectors = np.column_stack([np.full(8, 0.9), np.arange(8)]).astype(np.float32)  # always acts
    names = [f"p{i}" for i in range(8)]
    _use(monkeypatch, _Scripted())
    counted = replay_stream(vectors, _context(widths), success, names, "x", "paper", 0.5, 0, 0, OPENING_M)
    assert counted.wide_after_failure == 2  # rows 4 and 5: the first wide success (row 0) and failure (2) not
    _use(monkeypatch, _Scripted())
    after_warmup = replay_stream(
        vectors, _context(widths), success, names, "x", "paper", 0.5, 0, 5, OPENING_M
    )
    assert (
        after_warmup.wide_after_failure == 1
    )  # only scored decisions count; the failure before still arms it
    _use(monkeypatch, _Scripted())
    wider_gripper = replay_stream(vectors, _context(widths), success, names, "x", "paper", 0.5, 0, 0, 0.2)
    assert wider_gripper.wide_after_failure == 0
    rates = pooled_rates([counted, wider_gripper])
    assert rates["wide_attempts_after_first_wide_failure"] == 2
    assert rates["wide_attempts_after_first_wide_failure_max_per_stream"] == 2


def test_every_ask_is_counted_by_its_cause(monkeypatch: pytest.MonkeyPatch) -> None:
    """κ̂'s own asks are "unsure", the tree's foreseen asks carry their rule; the causes add up to the help rate,
    with what would have succeeded and what was wider than the gripper counted apart."""
    scores = np.array([0.9, 0.2, 0.9, 0.9, 0.3, 0.9])
    success = np.array([True, True, False, False, False, True])
    foreseen = np.array(["", "", "missing", "infeasible", "", ""])
    vectors = np.column_stack([scores, np.arange(6)]).astype(np.float32)
    _use(monkeypatch, _Scripted())
    out = replay_stream(
        vectors,
        _context([0.05, 0.05, 0.05, 0.05, 0.10, 0.05]),
        success,
        [f"p{i}" for i in range(6)],
        "x",
        "paper",
        0.5,
        0,
        0,
        OPENING_M,
        foreseen=foreseen,
    )
    causes = pooled_rates([out])["help_by_cause"]
    assert causes == {
        "unsure": {
            "decisions": 2,
            "rate": round(2 / 6, 4),
            "would_have_succeeded": 1,
            "wider_than_gripper": 1,
        },
        "infeasible": {
            "decisions": 1,
            "rate": round(1 / 6, 4),
            "would_have_succeeded": 0,
            "wider_than_gripper": 0,
        },
        "missing": {
            "decisions": 1,
            "rate": round(1 / 6, 4),
            "would_have_succeeded": 0,
            "wider_than_gripper": 0,
        },
    }
    assert list(causes) == ["unsure", "infeasible", "missing"]  # most first, then by name
    twice = pooled_rates([out, out])["help_by_cause"]
    assert twice["unsure"]["decisions"] == 4 and twice["unsure"]["rate"] == causes["unsure"]["rate"]


def test_on_the_recorded_streams_the_causes_add_up_to_the_help_rate() -> None:
    """The shipped gate (the probe, the strict promise) on the development recording: every too-wide ask is of a
    product perceived wider than the gripper, and the set-backs are the aborted probes."""
    from scone_bt.benchmarks.gate import replay_args, stream_results
    from scone_bt.benchmarks.replay import SET_BACK_CAUSES
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.gate.probe import ProbeOptions

    args = replay_args(str(REPO / "tools/data/sc_slide"))
    rates = pooled_rates(
        stream_results(
            load_streams(args, oracle=False), "physical", "budget", 0.15, args, probe=ProbeOptions()
        )
    )
    causes = rates["help_by_cause"]
    assert abs(sum(c["rate"] for c in causes.values()) - rates["help_rate"]) < 1e-3
    assert causes["too-wide"]["wider_than_gripper"] == causes["too-wide"]["decisions"] > 0
    set_back = [causes[c] for c in SET_BACK_CAUSES if c in causes]
    assert sum(c["decisions"] for c in set_back) == round(rates["aborted_rate"] * rates["decisions"])
    assert sum(c["would_have_succeeded"] for c in set_back) == rates["aborted_would_have_succeeded"]
    # the fingers' word is rarely wrong; κ̂'s doubt without credit (the strict promise's price) mostly is
    felt, unsure = causes["set-back-felt"], causes["set-back-unsure"]
    assert felt["would_have_succeeded"] < 0.1 * felt["decisions"]
    assert unsure["would_have_succeeded"] > 0.5 * unsure["decisions"]


def test_a_seeded_replay_repeats_exactly() -> None:
    vectors, context, success, products = _physical_stream()

    def replay(seed: int) -> StreamResult:
        return replay_stream(
            vectors,
            context,
            success,
            products,
            "physical",
            "budget",
            0.1,
            seed,
            0,
            OPENING_M,
            budget=BudgetOptions(start_margin=3.0),  # a start at which this stream explores
        )

    first = replay(0)
    assert replay(0) == first
    assert first.explored > 0  # the seeded exploration draws are part of what repeats
    assert len({repr(replay(seed)) for seed in range(4)}) > 1  # and the seed is what drives them


def _tiny_datasets(folder: Path) -> Path:
    """Two streams of 15 real executions each, in the generator's CSV schema."""
    folder.mkdir()
    for name, source, start in (("a", "p00_nominal.csv", 0), ("b", "p07_rushed_planner.csv", 40)):
        lines = (REPO / "tools" / "data" / "sc" / source).read_text().splitlines()
        (folder / f"{name}.csv").write_text("\n".join([lines[0], *lines[1 + start : 16 + start]]) + "\n")
    return folder


_PER_TARGET = (
    "success_rate",
    "help_rate",
    "over_ask_rate",
    "over_step_rate",
    "attempt_failure_rate",
    "attempt_failure_rate_novel",
    "wide_attempts_after_first_wide_failure",
)


def test_scone_bench_gate_reports_the_issues_keys(tmp_path: Path) -> None:
    report_path = tmp_path / "gate.json"
    argv = [
        "gate",
        "--datasets",
        str(_tiny_datasets(tmp_path / "sc")),
        "--embedder",
        "onehot",
        "--warmup",
        "3",
    ]
    assert main([*argv, "--json", str(report_path)]) == 0
    report = json.loads(report_path.read_text())
    assert report["datasets"] == ["a", "b"]
    for key in ("attempt_failure_rate", "help_rate", "attempt_failure_rate_novel"):
        assert key in report["default"]
    assert 0.0 <= report["default"]["help_rate"] <= 1.0
    methods = report["methods"]
    # the clairvoyant that never fails depends on the data alone: the same in the default and in every method
    never_fails = report["default"]["help_rate_floor_without_failures"]
    assert never_fails is not None and 0.0 <= never_fails <= 1.0
    assert {m["help_rate_floor_without_failures"] for p in methods.values() for m in p.values()} == {
        never_fails
    }
    assert {"budget:physical", "fixed:physical", "conformal", "paper", "oracle"} <= set(methods)
    for name, per_target in methods.items():
        expected = {"0.5"} if name == "paper" else {f"{a:g}" for a in TARGETS}
        assert set(per_target) == expected, name
        for target, metrics in per_target.items():
            missing = [k for k in _PER_TARGET if k not in metrics]
            assert not missing, (name, target, missing)
            assert metrics["decisions"] == 2 * (15 - 3)
            # no gate asks less than a clairvoyant at its own failure rate
            if metrics["help_rate_floor"] is not None:
                assert metrics["help_rate"] >= metrics["help_rate_floor"], (name, target)
    # the default gate started at every 10th row: 15-row streams start at rows 0 and 10, the first is the report's
    over = report["default"]["over_starts"]
    assert (over["step"], over["starts"]) == (10, 2)
    assert over["help_rate_min"] <= report["default"]["help_rate"] <= over["help_rate_max"]
    assert over["help_rate_min"] <= over["help_rate_mean"] <= over["help_rate_max"]


def test_the_budget_gate_never_attempts_what_is_wider_than_its_gripper(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    widths = [0.10, 0.03, 0.09, 0.05]
    success = np.array([True, True, False, True])
    vectors = np.column_stack([np.full(4, 0.99), np.arange(4)]).astype(np.float32)  # κ̂ is sure of every row
    names = [f"p{i}" for i in range(4)]
    learnt = _Scripted()
    _use(monkeypatch, learnt)
    out = replay_stream(vectors, _context(widths), success, names, "x", "budget", 0.15, 0, 0, OPENING_M)
    assert [i for i, _ in learnt.learnt] == [1, 3]  # the two wide products are asked about, never learnt
    assert out.all_attempts == 2
    paper = _Scripted()
    _use(monkeypatch, paper)
    replay_stream(vectors, _context(widths), success, names, "x", "paper", 0.15, 0, 0, OPENING_M)
    assert [i for i, _ in paper.learnt] == [0, 1, 2, 3]  # the paper's gate has no such rule


@pytest.mark.parametrize(
    ("name", "content", "expected"),
    [
        ("figure.txt", None, "unknown figure format '.txt'; give a file ending in one of .png, .svg, .pdf"),
        ("folder.png", "dir", "is a folder; give a file path"),
        ("data.png", "a,b\n1,2\n", "exists and is not an image (PNG, SVG or PDF); it is not overwritten"),
    ],
)
def test_a_bad_plot_path_is_refused_before_the_replay_runs(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    name,
    content,
    expected,
) -> None:
    import scone_bt.benchmarks.gate as gate

    monkeypatch.setattr(gate, "_replay", lambda *a: pytest.fail("the replay ran"))
    plot = tmp_path / name
    if content == "dir":
        plot.mkdir()
    elif content is not None:
        plot.write_text(content)
    assert main(["gate", "--plot", str(plot)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err, err
    if content not in (None, "dir"):
        assert plot.read_text() == content  # never overwritten


def test_the_report_is_out_before_the_figure_and_a_figure_replaces_only_a_figure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import scone_bt.benchmarks.gate as gate

    def broken(report: object, path: Path) -> None:
        raise RuntimeError("cannot draw")

    folder = _tiny_datasets(tmp_path / "data")
    argv = ["gate", "--datasets", str(folder), "--embedder", "onehot", "--warmup", "3", "--no-sweep"]
    argv += ["--json", str(tmp_path / "g.json"), "--plot", str(tmp_path / "g.png")]
    monkeypatch.setattr(gate, "_plot", broken)
    monkeypatch.delenv("SCONE_BT_DEBUG", raising=False)
    assert main(argv) == 1  # a program error, one line
    assert json.loads(capsys.readouterr().out)["benchmark"] == "gate"
    assert json.loads((tmp_path / "g.json").read_text())["benchmark"] == "gate"
    monkeypatch.undo()
    old = tmp_path / "old.svg"
    old.write_text('<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"></svg>\n')
    old.chmod(0o640)
    report = {"methods": {}, "budget_promise": {}}
    gate._plot(report, old)  # an empty figure is still a figure
    assert "<svg" in old.read_text() and (old.stat().st_mode & 0o777) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "g.json", "old.svg"]  # no temporary left


def test_prior_teaches_the_same_robot_first_and_reports_the_gap(tmp_path: Path, capsys) -> None:
    """--prior DIR: κ̂ first learns the same-named stream of DIR; the report pairs the executions and says when
    the budget keeps its promise again. The prior here is the same outcomes with one execution flipped."""
    from scone_bt.benchmarks.cross_engine import CROSS_ENGINE_TARGETS

    moved = _tiny_datasets(tmp_path / "moved")
    prior = tmp_path / "prior"
    prior.mkdir()
    for name in ("a", "b"):
        lines = (moved / f"{name}.csv").read_text().splitlines()
        if name == "a":  # execution 2 succeeded on the other engine
            cells = lines[3].split(",")
            assert cells[0] == "2"
            cells[4], cells[5] = ("failure", "grasp") if cells[4] == "success" else ("success", "")
            lines[3] = ",".join(cells)
        (prior / f"{name}.csv").write_text("\n".join(lines) + "\n")
    base = ["gate", "--datasets", str(moved), "--embedder", "onehot", "--warmup", "3", "--no-sweep"]
    out = tmp_path / "g.json"
    assert main([*base, "--prior", str(prior), "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["methods"] == {} and report["prior_datasets"] == ["a", "b"]
    cross = report["cross_engine"]
    assert set(cross["default"]) == {f"{a:g}" for a in CROSS_ENGINE_TARGETS}
    for row in cross["default"].values():
        for label in ("prior", "cold"):
            assert set(row[label]["recovery_decisions"]) == {"a", "b"}
            assert isinstance(row[label]["meets_target"], bool)
    gap = cross["profiles"]
    assert gap["b"]["flipped"] == [] and gap["b"]["success_rate"] == gap["b"]["success_rate_prior"]
    assert [f["index"] for f in gap["a"]["flipped"]] == [2] and gap["a"]["matched"] == 15
    assert cross["pooled"]["matched"] == 30
    # cold (no --prior) has no cross-engine section; a prior without the stream is one line
    assert main([*base, "--json", str(tmp_path / "cold.json")]) == 0
    assert "cross_engine" not in json.loads((tmp_path / "cold.json").read_text())
    (prior / "b.csv").unlink()
    capsys.readouterr()
    assert main([*base, "--prior", str(prior)]) == 2
    err = capsys.readouterr().err.strip()
    assert "--prior" in err and "no dataset 'b'" in err and "\n" not in err


def test_probe_on_datasets_without_probe_readings_is_one_line(tmp_path: Path, capsys) -> None:
    """``--probe`` on datasets none of which recorded the heft test would replay without it, saying so only in
    ``default.probe``: it is a one-line error naming the folder, the columns and the datasets that have them. Without
    ``--probe`` (the tree's setting) the same datasets replay."""
    folder = _tiny_datasets(tmp_path / "plain")
    base = ["gate", "--datasets", str(folder), "--embedder", "onehot", "--warmup", "3", "--no-sweep"]
    capsys.readouterr()
    assert main([*base, "--probe"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--probe" in err and str(folder) in err
    assert "probe_held" in err and "tools/data/sc_probe" in err
    assert main([*base, "--probe", "--no-replay", "--unseen"]) == 2  # the unseen section replays too
    assert main([*base, "--json", str(tmp_path / "g.json")]) == 0
    assert json.loads((tmp_path / "g.json").read_text())["default"]["probe"] is False


def test_the_replay_of_a_probing_robot_reads_the_streams_with_probe_readings_by_default() -> None:
    """The shipped tree probes: a plain `scone-bench gate` replays tools/data/sc_probe (tools/data/sc had no
    readings, so the shipped robot was replayed without its probe); ``--no-probe`` reads tools/data/sc, and
    ``--datasets`` always wins."""
    import argparse

    from scone_bt.benchmarks.gate import _tree_defaults
    from scone_bt.benchmarks.replay_streams import datasets_folder

    def folder(**flags) -> Path:
        args = argparse.Namespace(**{"datasets": None, "probe": None, "exploration_credit": None, **flags})
        _tree_defaults(args)
        return datasets_folder(args)

    assert folder().parts[-2:] == ("data", "sc_slide")
    assert folder(probe=False).parts[-2:] == ("data", "sc")
    assert folder(datasets="runs/mine", probe=True) == Path("runs/mine")


def test_an_episode_counts_an_aborted_probe_apart_and_its_ask_as_help() -> None:
    """``--episodes``: the set-back is not a failure or an attempt; the ask that follows it is help."""
    from scone_bt.benchmarks.gate_episodes import episode_counts
    from scone_bt.events import ActOutcome, HelpRequested, ProbeAborted

    events = [
        ProbeAborted(1.0, "Put olive oil on table", "olive oil", "the olive oil slips in my fingers"),
        HelpRequested(2.0, "Put olive oil on table", "olive oil"),
        ActOutcome(3.0, "Put salt on table", "salt", True, None),
    ]
    counts = episode_counts(events)
    assert (counts["aborted"], counts["help"], counts["attempts"], counts["failures"]) == (1, 1, 1, 0)


def test_an_episode_counts_the_probes_and_their_seconds() -> None:
    """``--episodes``: hefted decisions, seconds in attempts and in set-backs (where the probe's time goes)."""
    from scone_bt.benchmarks.gate_episodes import episode_counts
    from scone_bt.events import ActOutcome, DecisionMade, ProbeAborted
    from scone_bt.gate.types import DecisionKind

    act = DecisionKind.ACT
    events = [
        DecisionMade(0.5, 1, "add oil", "Put olive oil on table", 0.8, 0.5, act, probe=True),
        ProbeAborted(9.0, "Put olive oil on table", "olive oil", "the olive oil slips in my fingers", 8.5),
        DecisionMade(12.0, 1, "add salt", "Put salt on table", 0.8, 0.9, act),
        ActOutcome(23.0, "Put salt on table", "salt", True, None, 11.0),
    ]
    counts = episode_counts(events)
    assert (counts["probed"], counts["act_s"], counts["aborted_s"]) == (1, 11.0, 8.5)


def test_what_the_robot_knows_it_cannot_do_before_moving_is_asked_for(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A target not detected or one no plan reaches: the tree asks for it before the arm moves (ask_for_missing,
    infeasible_decision), so the replay asks too, whatever κ̂ says: no attempt, no failure of the budget. As the
    tree stores it, κ̂ learns a failure at planning from an infeasible plan, nothing from a target it never saw."""
    from dataclasses import replace

    from scone_bt.benchmarks.replay_streams import foreseen
    from scone_bt.benchmarks.self_confidence.dataset import Dataset
    from scone_bt.experience.types import CONTEXT_FIELDS

    n = 7
    context = _context([0.05] * n)
    context[1, CONTEXT_FIELDS.index("detected")] = 0.0  # the camera did not see row 1's target
    stages = ("", "perception", "planning", "grasp", "", "ik", "planning")
    details = (
        "placed upright on the table",
        "target not detected (5 products seen)",
        "every grasp of p2 collides with shelf_tier1 (14 tried)",
        "the fingers closed without holding the object",
        "placed upright on the table",
        "no IK solution for any grasp of p5 at the back",
        "no path to any grasp of p6: timed out",  # the planner ran out of time: the tree attempts it
    )
    data = Dataset(
        "s",
        tuple(f"Put p{i} on table" for i in range(n)),
        tuple(f"p{i}" for i in range(n)),
        np.array([s == "" for s in stages]),
        stages,
        context={"detected": context[:, CONTEXT_FIELDS.index("detected")]},
        details=details,
    )
    known = foreseen(data)
    assert known.tolist() == ["", "missing", "infeasible", "", "", "infeasible", ""]
    assert foreseen(replace(data, details=())).tolist() == ["", "missing", "", "", "", "", ""]

    vectors = np.column_stack([np.full(n, 0.9), np.arange(n)]).astype(np.float32)  # κ̂ sure of every one
    success = data.success
    kappa = _Scripted()
    _use(monkeypatch, kappa)
    trace: list = []
    out = replay_stream(
        vectors,
        context,
        success,
        list(data.objects),
        "x",
        "budget",
        0.15,
        0,
        0,
        OPENING_M,
        trace=trace,
        foreseen=known,
    )
    assert kappa.learnt == [(0, True), (2, False), (3, False), (4, True), (5, False), (6, False)]
    assert (out.all_attempts, out.all_failures, out.all_asked) == (4, 2, 3)
    assert [d.rule for d in trace] == ["", "missing", "infeasible", "", "", "infeasible", ""]
    assert "cannot see the p1" in trace[1].reason

    _use(monkeypatch, kappa := _Scripted())
    blind = replay_stream(vectors, context, success, list(data.objects), "x", "budget", 0.15, 0, 0, OPENING_M)
    # without it: the failed attempts the robot never makes
    assert (blind.all_attempts, blind.all_failures) == (7, 5)


def test_a_warmup_that_leaves_nothing_to_score_is_one_line(tmp_path: Path, capsys) -> None:
    folder = _tiny_datasets(tmp_path / "plain")
    capsys.readouterr()
    argv = ["gate", "--datasets", str(folder), "--embedder", "onehot", "--no-sweep", "--warmup", "100000"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--warmup 100000: leaves no decision to score (the shortest stream has" in err


def test_the_gate_after_the_move_is_the_shipped_gate_with_its_probe(tmp_path: Path) -> None:
    """With probe readings in the datasets, the cross-engine section replays the default gate as ``default.*`` does
    (the heft probe on): its taught figures at the default α are the report's own."""
    moved, prior = tmp_path / "moved", tmp_path / "prior"
    for folder, source in ((moved, "sc_mujoco_probe"), (prior, "sc_probe")):
        folder.mkdir()
        for name in ("p01_weak_gripper", "p02_slippery_fingers"):  # the streams the probe sets most back on
            lines = (REPO / "tools/data" / source / f"{name}.csv").read_text(encoding="utf-8").splitlines()
            (folder / f"{name}.csv").write_text("\n".join(lines[:41]) + "\n", encoding="utf-8")
    out = tmp_path / "g.json"
    args = ["gate", "--datasets", str(moved), "--prior", str(prior), "--embedder", "onehot", "--warmup", "5"]
    assert main([*args, "--no-sweep", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    cross, default = report["cross_engine"], report["default"]
    assert cross["probe"] is True and default["probe"] is True and default["aborted_rate"] > 0
    taught = cross["default"][f"{default['target_failure_rate']:g}"]["prior"]
    assert (taught["attempt_failure_rate"], taught["help_rate"]) == (
        default["attempt_failure_rate"],
        default["help_rate"],
    )
