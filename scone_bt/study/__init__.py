"""The trust study toolkit: tablet UI, study sessions with durable logging, questionnaires, simulated participants
and the paper's Bayesian analysis. Heavy parts (FastAPI, PyMC) are imported by their own modules only.

The names below load on first use (PEP 562), so importing a light submodule (`scone_bt.study.ui_args`, the --ui
flags scone-run's parser needs) does not load the trust model and the study log.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
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

_HOMES = {
    "Condition": "design",
    "Group": "design",
    "SessionPlan": "design",
    "assign_group": "design",
    "plan_session": "design",
    "StudyLog": "log",
    "StudyLogError": "log",
    "MDMT_PERFORMANCE": "questionnaires",
    "TPS_HRI_14": "questionnaires",
    "QUESTIONNAIRES": "questionnaires",
    "Questionnaire": "questionnaires",
    "get_questionnaire": "questionnaires",
    "SimulatedParticipant": "trust",
    "TrustfulHuman": "trust",
    "TrustParameters": "trust",
}

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


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'scone_bt.study' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"scone_bt.study.{home}"), name)
    globals()[name] = value  # once loaded, an ordinary attribute
    return value
