"""Draws the behaviour tree: its graph, each behaviour's status on the timeline and the tree as text."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import py_trees
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.colours import STATUS_COLOURS
from scone_bt.viz.render import STATUSES, TreeNode, flatten_tree, layout_tree, status_text, tree_text
from scone_bt.viz.sinks import Sinks

__all__ = ["TreeDrawer"]

_Signature = tuple[tuple[int, str, Any, str, int], ...]


def _tree_signature(root: Any) -> _Signature:
    """Identity, name, status, feedback and child count of every behaviour, in pre-order (flatten_tree's order):
    equal signatures, nothing to log."""
    out = []
    stack = [root]
    while stack:
        behaviour = stack.pop()
        children = getattr(behaviour, "children", None) or ()
        out.append(
            (
                id(behaviour),
                behaviour.name,
                behaviour.status,
                getattr(behaviour, "feedback_message", ""),
                len(children),
            )
        )
        stack.extend(reversed(children))
    return tuple(out)


class TreeDrawer:
    """The tree's graph and text when a status or feedback changed; a node's status when it changed."""

    def __init__(self, sinks: Sinks) -> None:
        self._sinks = sinks
        self._shape: tuple[str, ...] = ()
        self._signature: _Signature = ()
        self._structure: tuple[tuple[int, str, int], ...] = ()
        self._nodes: list[TreeNode] = []
        self._state: dict[str, tuple[str, str]] = {}
        self._layout: dict[str, tuple[float, float]] = {}

    def log_tree(self, tree: Any) -> None:
        """A py_trees BehaviourTree or its root behaviour."""
        root = tree.root if isinstance(tree, py_trees.trees.BehaviourTree) else tree
        signature = _tree_signature(root)
        if signature == self._signature:
            return
        self._signature = signature
        nodes = self._nodes_now(root, signature)
        shape = tuple(n.node_id for n in nodes)
        if shape != self._shape:
            self._log_shape(nodes, shape)
        changed = status_changed = False
        for node in nodes:
            state = (node.status, node.feedback)
            previous = self._state.get(node.node_id)
            if previous == state:
                continue
            changed = True
            if previous is None or previous[0] != node.status:
                status_changed = True
                self._sinks.rec.log(f"{P.TREE_STATUS}/{node.node_id}", rr.StateChange(state=[node.status]))
            self._state[node.node_id] = state
        # The graph shows statuses only: a feedback message (most ticks' change) redraws the text alone.
        if status_changed:
            self._log_graph(nodes)
        if changed:
            self._sinks.rec.log(P.TREE_TEXT, rr.TextDocument(tree_text(nodes)))

    def _nodes_now(self, root: Any, signature: _Signature) -> list[TreeNode]:
        """The tree's nodes at this tick: walked again only when its behaviours changed, else the last walk's
        nodes with this tick's statuses and feedback (most ticks change a feedback message, nothing else)."""
        structure = tuple((s[0], s[1], s[4]) for s in signature)
        if structure != self._structure:
            self._structure, self._nodes = structure, flatten_tree(root)
            return self._nodes
        nodes = []
        for node, (_, _, status, feedback, _) in zip(self._nodes, signature, strict=True):
            status_now, feedback_now = status_text(status), str(feedback or "")
            if (status_now, feedback_now) != (node.status, node.feedback):
                node = replace(node, status=status_now, feedback=feedback_now)
            nodes.append(node)
        self._nodes = nodes
        return nodes

    def _log_shape(self, nodes: list[TreeNode], shape: tuple[str, ...]) -> None:
        """A new tree: its edges, its layout, and each node's status colours (static)."""
        self._shape = shape
        self._state = {}
        self._layout = layout_tree(nodes)
        edges = [(n.parent, n.node_id) for n in nodes if n.parent is not None]
        self._sinks.rec.log(P.TREE_GRAPH, rr.GraphEdges(edges, graph_type="directed"))
        for node in nodes:
            self._sinks.rec.log(
                f"{P.TREE_STATUS}/{node.node_id}",
                rr.StateConfiguration(values=list(STATUSES), colors=[STATUS_COLOURS[s] for s in STATUSES]),
                static=True,
            )

    def _log_graph(self, nodes: list[TreeNode]) -> None:
        self._sinks.rec.log(
            P.TREE_GRAPH,
            rr.GraphNodes(
                [n.node_id for n in nodes],
                positions=[self._layout[n.node_id] for n in nodes],
                labels=[f"{n.name}: {n.status.lower()}" for n in nodes],
                colors=[STATUS_COLOURS.get(n.status, STATUS_COLOURS["INVALID"]) for n in nodes],
                radii=[10.0 if n.is_leaf else 14.0 for n in nodes],
            ),
        )
