"""The simulated human cook: works through the recipe, helps when asked, and sometimes takes over."""

from scone_bt.human.simulated import ClarifyAnswer, FetchReason, HelpAnswer, HumanOptions, SimulatedHuman

__all__ = ["ClarifyAnswer", "FetchReason", "HelpAnswer", "HumanOptions", "SimulatedHuman"]
