"""The trust study toolkit: tablet UI, study sessions with durable logging, questionnaires, simulated participants
and the paper's Bayesian analysis. Heavy parts (FastAPI, PyMC) are imported by their own modules only."""

from scone_bt.study.design import Condition, Group, SessionPlan, assign_group, plan_session
from scone_bt.study.log import StudyLog, StudyLogError
from scone_bt.study.questionnaires import (
    MDMT_PERFORMANCE,
    QUESTIONNAIRES,
    TPS_HRI_14,
    Questionnaire,
    get_questionnaire,
)
from scone_bt.study.trust import SimulatedParticipant, TrustfulHuman, TrustParameters

__all__ = [
    "Condition",
    "Group",
    "SessionPlan",
    "assign_group",
    "plan_session",
    "StudyLog",
    "StudyLogError",
    "MDMT_PERFORMANCE",
    "TPS_HRI_14",
    "QUESTIONNAIRES",
    "Questionnaire",
    "get_questionnaire",
    "SimulatedParticipant",
    "TrustfulHuman",
    "TrustParameters",
]
