"""The simulated human cook: works through the recipe, helps when asked, and sometimes takes over."""

from scone_bt.human.simulated import HumanEvent, HumanOptions, SimulatedHuman

__all__ = ["HumanEvent", "HumanOptions", "SimulatedHuman"]
