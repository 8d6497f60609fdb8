"""Experience: every observed outcome, stored durably so κ̂ can be rebuilt after any crash.

store = open_store("runs/experience.sqlite")              # or "postgresql://robot@fleet-db/scone" for a fleet
store.append(Outcome(time.time(), "Put salt on table", "salt", "minilm", success=True, robot_id="panda-1",
                     arm="panda"))
store.outcomes(**LearnFrom.SAME_MODEL.filters("panda-1", "panda", backend="sim"))  # its model, on PyBullet
"""

from scone_bt.experience.base import SCHEMA_VERSION, OutcomeStore, attempted_outcome_ids
from scone_bt.experience.learn_from import (
    BACKEND_KEY,
    LearnFrom,
    StoreFilters,
    on_backend,
    unlabelled_backend,
)
from scone_bt.experience.open import count_stored, open_store
from scone_bt.experience.postgres import PostgresExperienceStore, is_postgres_url, redact_url
from scone_bt.experience.store import APPLICATION_ID, ExperienceStore
from scone_bt.experience.types import Outcome, new_outcome_id

__all__ = [
    "APPLICATION_ID",
    "BACKEND_KEY",
    "SCHEMA_VERSION",
    "attempted_outcome_ids",
    "ExperienceStore",
    "LearnFrom",
    "Outcome",
    "OutcomeStore",
    "PostgresExperienceStore",
    "StoreFilters",
    "is_postgres_url",
    "new_outcome_id",
    "on_backend",
    "unlabelled_backend",
    "count_stored",
    "open_store",
    "redact_url",
]
