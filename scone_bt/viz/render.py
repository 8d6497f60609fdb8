"""Pure helpers that turn tick data into what a viewer shows: tree node lists, layouts and markdown panels."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.viz.snapshot import AffordanceRow, RecipeView

__all__ = [
    "STATUSES",
    "TreeNode",
    "slug",
    "flatten_tree",
    "status_text",
    "layout_tree",
    "tree_text",
    "rank_affordances",
    "affordances_markdown",
    "context_text",
    "decision_markdown",
    "recipe_markdown",
]

STATUSES = ("SUCCESS", "FAILURE", "RUNNING", "INVALID")
"""py_trees statuses, as logged."""

_SYMBOL = {"SUCCESS": "✓", "FAILURE": "✕", "RUNNING": "*", "INVALID": "-"}
_SLUG = re.compile(r"[^A-Za-z0-9_-]+")


def slug(name: str) -> str:
    """A name as one entity-path part: runs of other characters become '_' ('black pepper' → 'black_pepper')."""
    return _SLUG.sub("_", name.strip()).strip("_") or "_"


@dataclass(frozen=True)
class TreeNode:
    """One behaviour of a py_trees tree at one tick.

    Attributes:
        node_id: Path of slugged names from the root ("Root/Gate/Ask_help"), unique within the tree.
        name: The behaviour's own name.
        kind: Its class name (Sequence, Selector, a leaf's class).
        status: One of STATUSES.
        feedback: The behaviour's feedback message ('' when none).
        parent: node_id of the parent, None for the root.
        depth: 0 for the root.
        is_leaf: True when the behaviour has no children.
    """

    node_id: str
    name: str
    kind: str
    status: str
    feedback: str
    parent: str | None
    depth: int
    is_leaf: bool


def status_text(status: Any) -> str:
    """A py_trees status as logged ("SUCCESS", ...)."""
    return str(getattr(status, "value", status))


def flatten_tree(root: Any) -> list[TreeNode]:
    """Pre-order list of a py_trees tree's behaviours (root first, children in tick order)."""
    out: list[TreeNode] = []

    def visit(behaviour: Any, parent: str | None, depth: int, taken: set[str]) -> None:
        base = slug(str(behaviour.name))
        part, n = base, 1
        while part in taken:  # siblings that share a name stay distinct
            n += 1
            part = f"{base}_{n}"
        taken.add(part)
        node_id = part if parent is None else f"{parent}/{part}"
        children = list(getattr(behaviour, "children", []) or [])
        out.append(
            TreeNode(
                node_id=node_id,
                name=str(behaviour.name),
                kind=type(behaviour).__name__,
                status=status_text(behaviour.status),
                feedback=str(getattr(behaviour, "feedback_message", "") or ""),
                parent=parent,
                depth=depth,
                is_leaf=not children,
            )
        )
        siblings: set[str] = set()
        for child in children:
            visit(child, node_id, depth + 1, siblings)

    visit(root, None, 0, set())
    return out


def layout_tree(
    nodes: Sequence[TreeNode], dx: float = 260.0, dy: float = 44.0
) -> dict[str, tuple[float, float]]:
    """Tidy left-to-right positions (graph-view units): depth along x, leaves stacked along y, each parent
    centred beside its children. Trees are wider than deep, so this fills a landscape panel with legible labels."""
    children: dict[str | None, list[str]] = {}
    for node in nodes:
        children.setdefault(node.parent, []).append(node.node_id)
    depth = {node.node_id: node.depth for node in nodes}
    ys: dict[str, float] = {}
    next_leaf = [0.0]

    def place(node_id: str) -> float:
        kids = children.get(node_id, [])
        if not kids:
            ys[node_id] = next_leaf[0]
            next_leaf[0] += dy
        else:
            placed = [place(k) for k in kids]
            ys[node_id] = (placed[0] + placed[-1]) / 2
        return ys[node_id]

    for root_id in children.get(None, []):
        place(root_id)
    return {nid: (depth[nid] * dx, y) for nid, y in ys.items()}


def tree_text(nodes: Sequence[TreeNode]) -> str:
    """Indented text view: one line per behaviour with its status symbol and feedback message."""
    lines = []
    for node in nodes:
        mark = _SYMBOL.get(node.status, "?")
        kind = "" if node.is_leaf else f" ({node.kind})"
        feedback = (
            f" — {node.feedback}" if node.feedback and node.feedback.lower() != node.status.lower() else ""
        )
        lines.append(f"{'    ' * node.depth}[{mark}] {node.name}{kind}: {node.status.lower()}{feedback}")
    return "\n".join(lines)


def rank_affordances(rows: Sequence[AffordanceRow]) -> list[AffordanceRow]:
    """Most relevant first; ties keep their order; unknown (NaN) relevance last."""
    return sorted(rows, key=lambda r: -float(r[1]) if math.isfinite(float(r[1])) else math.inf)


def _num(value: float, digits: int) -> str:
    return "—" if not math.isfinite(value) else f"{value:.{digits}f}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def context_text(context: ExecutionContext | None) -> str:
    """An execution context in a few characters: tier, clearance, neighbours, perceived width × height (cm)."""
    if context is None:
        return ""

    def cm(v: float | None) -> str:
        return "?" if v is None else f"{100 * v:.0f}"

    tier = "?" if context.shelf_tier is None else str(context.shelf_tier)
    near = "?" if context.neighbours is None else str(context.neighbours)
    return (
        f"tier {tier} · gap {cm(context.clearance_m)} cm · {near} near · "
        f"{cm(context.detected_width_m)}×{cm(context.detected_height_m)} cm"
    )


def affordances_markdown(
    rows: Sequence[AffordanceRow],
    decision: Decision | None,
    contexts: Mapping[str, ExecutionContext] | None = None,
) -> str:
    """Ranked affordance table; the chosen action is marked with the gate's verdict.

    With ``contexts`` (action text → the context the gate perceived) a column shows each action's context.
    """
    if not rows:
        return "_no affordances: nothing detected_"
    chosen = decision.action if decision is not None else None
    verdict = ""
    if decision is not None and decision.kind is DecisionKind.ACT:
        verdict = "**ACT**"
    elif decision is not None and decision.kind is DecisionKind.ASK:
        verdict = "**ASK-HELP**"
    elif decision is not None and decision.kind is DecisionKind.CLARIFY:
        verdict = "**ASK-CLARIFY: which?**"
    candidates = set(decision.candidates) if decision is not None else set()
    lines = ["| # | action | relevance | confidence | gate |", "|---|---|---:|---:|---|"]
    if contexts:
        lines = [lines[0] + " context |", lines[1] + "---|"]
    for i, (text, relevance, confidence) in enumerate(rank_affordances(rows), start=1):
        mark = text == chosen or text in candidates
        name = f"**▶ {_cell(text)}**" if mark else _cell(text)
        line = f"| {i} | {name} | {_num(relevance, 3)} | {_num(confidence, 2)} | {verdict if mark else ''} |"
        if contexts:
            line += f" {context_text(contexts.get(text))} |"
        lines.append(line)
    return "\n".join(lines)


def decision_markdown(decision: Decision) -> str:
    """The gate's decision as a short card."""
    action = decision.action or (" or ".join(decision.candidates) if decision.candidates else "—")
    later = " (needed later)" if decision.need == "later" else ""
    return (
        f"### {decision.kind.label}: {_cell(action)}{later}\n\n"
        f"relevance {_num(decision.relevance, 3)} · confidence {_num(decision.confidence, 2)}\n\n{decision.reason}"
    )


def recipe_markdown(recipe: RecipeView) -> str:
    """Title, then every step: done ones ticked and struck through, the current one highlighted."""
    lines = [f"## {recipe.title}", ""]
    for i, (step, done) in enumerate(zip(recipe.steps, recipe.done, strict=True), start=1):
        if done:
            lines.append(f"{i}. ✔ ~~{step}~~")
        elif recipe.current is not None and i - 1 == recipe.current:
            lines.append(f"{i}. ▶ **{step}**")
        else:
            lines.append(f"{i}. ○ {step}")
    if recipe.current is None:
        lines += ["", "_recipe finished_"]
    return "\n".join(lines)
