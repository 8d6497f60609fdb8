"""Building the behaviour tree from its declarative file (trees/*.yaml)."""

from scone_bt.tree.build import TreeSpec, build_tree, load_tree_spec, render_tree

__all__ = ["TreeSpec", "build_tree", "load_tree_spec", "render_tree"]
