"""The tree file's `parameters:` section; defined in `scone_bt.config.tree_parameters` (behaviours read it too)."""

from scone_bt.config.tree_parameters import PARAMETER_NAMES, TreeParameters

__all__ = ["TreeParameters", "PARAMETER_NAMES"]
