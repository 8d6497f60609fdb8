"""Progress of a benchmark that runs for more than a few seconds: a tqdm bar on stderr.

The report is JSON on stdout, so progress never goes there; ``--quiet`` turns it off.
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["progress_bar"]


def progress_bar(total: int, desc: str, quiet: bool = False, unit: str = "step") -> Any:
    """A tqdm bar on stderr over ``total`` units (a context manager; ``update``, ``set_postfix_str``).

    Disabled with ``quiet``: then it prints nothing and its methods do nothing.
    """
    from tqdm import tqdm

    return tqdm(
        total=total, desc=desc, unit=unit, file=sys.stderr, disable=quiet, leave=False, mininterval=0.2
    )
