"""Experience: every observed outcome, stored durably so κ̂ can be rebuilt after any crash.

store = ExperienceStore("runs/experience.sqlite")
store.append(Outcome(time.time(), "Put salt on table", "salt", "minilm", success=True))
store.outcomes(embedder="minilm")
"""

from scone_bt.experience.store import APPLICATION_ID, SCHEMA_VERSION, ExperienceStore
from scone_bt.experience.types import Outcome

__all__ = ["APPLICATION_ID", "SCHEMA_VERSION", "ExperienceStore", "Outcome"]
