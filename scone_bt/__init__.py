"""SCONE-BT: an assistive cooking robot that learns its own competence from semantic action embeddings.

The subpackages follow the data flow of one tick of the behaviour tree:

    world → perception → affordances → embedding → relevance → confidence → gate → motion / human
    → experience, with viz (rerun) watching every tick and behaviours/tree wiring it together.
"""

__version__ = "0.1.0"
__all__ = ["__version__"]
