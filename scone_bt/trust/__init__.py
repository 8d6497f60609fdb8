"""The person's trust in the robot: human trust ratings (data), a trust model that transfers across actions through
ζ fitted to them (transfer), and the estimate the robot keeps online during an episode (estimate).

Submodules are imported directly (``from scone_bt.trust.transfer import TransferModel``); this package imports
nothing heavy.
"""

__all__: list[str] = []
