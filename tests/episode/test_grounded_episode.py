"""The shipped tree's grounded κ̂ in a whole seeded episode (PyBullet DIRECT), and a restart that rebuilds it."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.confidence import grounded_features, make_estimator
from scone_bt.confidence.grounded import is_grounded
from scone_bt.episode import EpisodeOptions, EpisodeResources, run_episode
from scone_bt.events import ActOutcome, DecisionMade, PlanInfeasible, ProbeAborted
from scone_bt.experience import open_store
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import DecisionKind
from scone_bt.tree import load_tree_spec
from tests.behaviours.fakes import FakeRobot


def test_the_shipped_tree_uses_the_estimator_the_gate_replay_chose() -> None:
    """The tree's κ̂ is the one the committed gate replay reports as the default (chosen by the gate metrics, not by
    Algorithm 1 alone: docs/results/gate.md), and it is grounded."""
    from pathlib import Path

    params = load_tree_spec("assistive_cooking").parameters
    gate = json.loads((Path(__file__).parents[2] / "docs/results/gate.json").read_text())
    assert params["estimator"] == gate["default"]["estimator"]
    assert f"budget:{params['estimator']}" in gate["methods"]
    assert is_grounded(make_estimator(params["estimator"]))


def _set_back_on_doubt(events: list) -> list[DecisionMade]:
    """The ACT decisions whose heft test ended in a set-back on κ̂'s own doubt (the event that ends an act is the
    next ActOutcome or ProbeAborted; the fingers' own word is stored as a failure, the doubt is not)."""
    doubted, pending = [], None
    for e in events:
        if isinstance(e, DecisionMade) and e.verdict is DecisionKind.ACT:
            pending = e
        elif isinstance(e, ProbeAborted) and pending is not None:
            if e.reason.startswith("I am not sure"):
                doubted.append(pending)
            pending = None
        elif isinstance(e, ActOutcome):
            pending = None
    return doubted


@pytest.mark.slow
def test_a_grounded_episode_stores_contexts_and_a_restart_rebuilds_from_them(tmp_path) -> None:
    db = tmp_path / "panda.db"
    events: list = []
    options = EpisodeOptions(distractors=4, behaviour=BehaviourOptions(seed=0, experience_path=db))
    summary = run_episode(options, printer=lambda _line: None, on_event=events.append)
    assert summary.completed and summary.attempted >= 1
    decisions = [e for e in events if isinstance(e, DecisionMade) and e.action is not None]
    # The cold start is the prior, as with every estimator: 0.50 at the first decision.
    assert decisions[0].confidence == pytest.approx(0.5)
    seen = [d for d in decisions if d.rule != "missing"]  # a missing item has no detection, so no context
    for d in seen:  # each decision about an action it sees carries the context κ̂ saw for it
        assert d.context is not None and d.context.detected is True and d.context.shelf_tier is not None
    # stored: every attempt, and every plan found infeasible before committing (a failure at planning); not a
    # product the heft test set back on κ̂'s own doubt (taught nothing, like an ask)
    doubted = _set_back_on_doubt(events)
    labelled = [
        d
        for d in seen
        if (d.verdict is DecisionKind.ACT or d.rule == "infeasible") and not any(d is x for x in doubted)
    ]
    acted = [d.context for d in labelled]
    with open_store(db) as store:
        stored = store.outcomes()
    outcomes = [e for e in events if isinstance(e, ActOutcome | PlanInfeasible)]
    assert [o.success for o in stored] == [isinstance(o, ActOutcome) and o.success for o in outcomes]
    # what the robot perceived, as it decided; an action it hefted first adds what its fingers felt (the felt_
    # fields, experience.felt), none of which the decision knew
    felt = [f.name for f in dataclasses.fields(ExecutionContext) if f.name.startswith("felt_")]
    perceived = [dataclasses.replace(o.execution, **dict.fromkeys(felt)) for o in stored]
    assert perceived == acted[: len(stored)]
    # the shipped tree hefts what it is unsure of
    assert any(o.execution.felt_held is not None for o in stored)

    # A restarted robot rebuilds the grounded κ̂ from those outcomes and their contexts.
    lines: list[str] = []
    resolved = options.behaviour.resolve(load_tree_spec("assistive_cooking").parameters)
    with EpisodeResources(FakeRobot(), resolved, "panda", "panda", lines.append) as res:
        est = res.estimator()
        assert is_grounded(est) and est.n_observations == len(stored)
        assert any(f"κ̂ rebuilt from {len(stored)} stored outcomes" in line for line in lines)
        X = grounded_features(res.embedder().embed([o.action for o in stored]), [o.execution for o in stored])
        belief = np.asarray(est.predict(X))
    assert np.isfinite(belief).all() and ((belief >= 0) & (belief <= 1)).all()
    y = np.array([o.success for o in stored])
    if (
        y.any() and not y.all()
    ):  # with both labels stored, the rebuilt κ̂ ranks its failures below its successes
        assert belief[~y].mean() < belief[y].mean()
