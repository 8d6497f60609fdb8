"""py_trees behaviours: thin wrappers that move data between the stages via the blackboard.

Each behaviour takes narrow collaborators in its constructor (`ports`: the robot, the human channel, the event
sink, κ̂, the outcome recorder, the attempt history, the planner seeds); `from_context` wires them from an
`EpisodeContext`, which only the tree builder sees.
"""

from scone_bt.behaviours.affordances import GenerateAffordances
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext, OutcomeLabels
from scone_bt.behaviours.gate import ConfidenceGate, DecisionIs
from scone_bt.behaviours.gate_config import GatePorts, GateSettings
from scone_bt.behaviours.help import AskForHelp, AskToClarify, ClearGripper, WaitForHuman
from scone_bt.behaviours.options import BehaviourOptions
from scone_bt.behaviours.outcome import ObserveOutcome, RecordInfeasible, UpdateSelfConfidence
from scone_bt.behaviours.perceive import Perceive
from scone_bt.behaviours.pick_and_place import PickAndPlace
from scone_bt.behaviours.recipe import RecipeDone
from scone_bt.behaviours.relevance import RankByRelevance

BEHAVIOURS = {
    cls.__name__: cls
    for cls in (
        Perceive,
        GenerateAffordances,
        RankByRelevance,
        ConfidenceGate,
        DecisionIs,
        AskForHelp,
        AskToClarify,
        WaitForHuman,
        PickAndPlace,
        ObserveOutcome,
        RecordInfeasible,
        UpdateSelfConfidence,
        ClearGripper,
        RecipeDone,
    )
}

__all__ = [
    "AskForHelp",
    "AskToClarify",
    "BEHAVIOURS",
    "BehaviourOptions",
    "ClearGripper",
    "ConfidenceGate",
    "DecisionIs",
    "EpisodeContext",
    "GatePorts",
    "GateSettings",
    "GenerateAffordances",
    "Keys",
    "ObserveOutcome",
    "OutcomeLabels",
    "Perceive",
    "PickAndPlace",
    "RankByRelevance",
    "RecipeDone",
    "RecordInfeasible",
    "StageBehaviour",
    "UpdateSelfConfidence",
    "WaitForHuman",
]
