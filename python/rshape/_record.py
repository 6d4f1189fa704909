"""Typed views of the library's JSON reports: attribute access, numpy arrays for lists of
numbers, nested records for objects; ``to_dict()`` gives the plain JSON content back."""

from __future__ import annotations

import json
from typing import Any

import numpy as np


def _convert(v: Any) -> Any:
    if isinstance(v, dict):
        return Record(v)
    if isinstance(v, list):
        if v and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
            return np.asarray(v, dtype=float)
        if v and all(isinstance(x, list) and len(x) == 2 and all(isinstance(y, (int, float)) for y in x) for x in v):
            # [re, im] pairs (poles, zeros): complex numbers
            return np.asarray([complex(a, b) for a, b in v])
        return [_convert(x) for x in v]
    return v


class Record:
    """A report section with the same fields as the CLI's JSON (``rshape … --json``)."""

    def __init__(self, data: dict):
        object.__setattr__(self, "_data", data)
        for k, v in data.items():
            object.__setattr__(self, k, _convert(v))

    @classmethod
    def from_json(cls, text: str) -> "Record":
        return cls(json.loads(text))

    def to_dict(self) -> dict:
        """The JSON content, as parsed."""
        return self._data

    def keys(self):
        return self._data.keys()

    def __getitem__(self, k):
        return getattr(self, k)

    def __contains__(self, k):
        return k in self._data

    def __setattr__(self, k, v):
        raise AttributeError("rshape results are read-only")

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={_short(getattr(self, k))}" for k in list(self._data)[:8])
        more = ", …" if len(self._data) > 8 else ""
        return f"{type(self).__name__}({inner}{more})"


def _short(v: Any) -> str:
    if isinstance(v, np.ndarray):
        return f"array({v.shape[0]})"
    if isinstance(v, list):
        return f"[{len(v)} items]"
    if isinstance(v, Record):
        return type(v).__name__ + "(…)"
    return repr(v)
