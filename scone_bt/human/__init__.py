"""The simulated human cook: works through the recipe, helps when asked, and sometimes takes over."""

from scone_bt.human.simulated import FetchReason, HumanOptions, SimulatedHuman

__all__ = ["FetchReason", "HumanOptions", "SimulatedHuman"]
