"""Reading the fitting study's rows (CSV cells as written by :mod:`brdfkit.fitting.batch`),
shared by the report's verdicts, figures and writer."""

from __future__ import annotations

import json
import math

from brdfkit.status import STATUS


def _f(x) -> float:
    """A CSV cell as a float (NaN when empty)."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def _params(row) -> dict:
    return json.loads(row["params"]) if row.get("params") else {}


def _name(spec: str) -> str:
    return str(spec).rsplit(":", 1)[-1]


def _ok(row) -> bool:
    return row.get("status") in ("ok", "not-converged")


def _by_target(rows) -> dict:
    return {r["target"]: r for r in rows if _ok(r)}


def _fit_status(row) -> int:
    s = _f(row.get("fit_status"))
    if math.isfinite(s):
        return int(s)
    # rows written before fit_status existed: read the message
    msg = str(row.get("message", ""))
    for code, text in STATUS["fit"].messages.items():
        if msg.startswith(text):
            return code
    return -1
