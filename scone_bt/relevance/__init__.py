"""ρ, relevance: rank actions by similarity to an instruction; a learnt threshold marks instructions
irrelevant (no action passes) or completed (every passing action is done)."""

from scone_bt.relevance.filter import (
    InstructionProgress,
    InstructionStatus,
    RelevanceFilter,
    instruction_progress,
)
from scone_bt.relevance.rank import rank_actions, relevance_matrix
from scone_bt.relevance.types import RankedAction

__all__ = [
    "InstructionProgress",
    "InstructionStatus",
    "RankedAction",
    "RelevanceFilter",
    "instruction_progress",
    "rank_actions",
    "relevance_matrix",
]
