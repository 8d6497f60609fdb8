"""Strict JSON for every report the project writes: NaN and infinities become null.

Python's `json` writes `NaN` and `Infinity` by default, which is not JSON: strict parsers (JavaScript's
`JSON.parse`, `jq`, most other languages) reject the whole file. A value that is not a number (say, R-hat from
one chain) is written as null instead.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

__all__ = ["clean_json", "dumps"]


def clean_json(obj: Any) -> Any:
    """`obj` with non-finite floats as None, numpy scalars as Python ones and tuples as lists."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, np.floating | np.integer | np.bool_):
        return clean_json(obj.item())
    if isinstance(obj, dict):
        return {k: clean_json(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean_json(v) for v in obj]
    return obj


def dumps(obj: Any, indent: int | None = 2, **kwargs: Any) -> str:
    """`json.dumps` of `clean_json(obj)`, refusing any non-finite float that is left (there is none)."""
    return json.dumps(clean_json(obj), indent=indent, allow_nan=False, **kwargs)
