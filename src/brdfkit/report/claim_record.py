"""
A paper's claim as a data record, and its verdict computed from numbers
=======================================================================

A :class:`Claim` is what a paper says (``statement``) and where (``location``: section,
equation, figure), how brdfkit computes it (``method``, the function ``compute``), the
tolerance its rule uses, and the rule (``rule``) that turns the computed numbers into a
verdict. Nothing in a record is a verdict: :func:`evaluate` runs ``compute`` and then
``rule`` every time, so a verdict can come out either way.

Verdicts (:data:`VERDICTS`):

- ``confirmed`` — the numbers agree with the claim within the tolerance;
- ``refuted`` — they do not;
- ``confirmed with a correction`` — the claim holds once a printed formula or statement
  is corrected; the record's ``correction`` says how (the corrected formula);
- ``undetermined`` — the computation cannot decide (its reason given), e.g. the data it
  needs are missing.

Public objects
--------------
- :class:`Claim`, :class:`Outcome`, :data:`VERDICTS`, :class:`Context`.
- :func:`evaluate` — a claim's result record (a JSON-ready dict).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["VERDICTS", "Claim", "Context", "Outcome", "evaluate", "json_ready"]

#: The verdicts a rule may return, in the order the report counts them.
VERDICTS = ("confirmed", "confirmed with a correction", "refuted", "undetermined")


@dataclass(frozen=True)
class Outcome:
    """What a rule decides: the verdict, why (with the numbers), and the correction of a
    printed formula or statement (``""`` when none is needed)."""

    verdict: str
    reason: str
    correction: str = ""


@dataclass(frozen=True)
class Context:
    """What a claim's computation may read: the fitting study's batch directory, and
    whether the run is the full one (paper-quality settings)."""

    study_dir: str
    full: bool = False


@dataclass(frozen=True)
class Claim:
    """One claim of one paper (module docstring).

    ``compute(ctx)`` returns the numbers (a dict of JSON-ready values); ``rule(numbers,
    tolerance)`` returns an :class:`Outcome`. Both are module-level functions, so a claim
    can be computed in a worker process by its ``id``.
    """

    id: str
    paper: str
    location: str
    statement: str
    method: str
    compute: Callable
    rule: Callable
    tolerance: float | None = None
    #: the paper's section the report files the claim under (e.g. "§3 Some typical shaders")
    section: str = ""


def json_ready(value):
    """*value* with NumPy scalars/arrays turned into floats/lists, non-finite floats into
    strings ("inf", "nan"), so that ``json.dumps`` writes strict JSON."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating | float):
        x = float(value)
        return x if math.isfinite(x) else str(x)
    return value


def evaluate(claim: Claim, ctx: Context) -> dict:
    """The claim's record with its computed ``numbers`` and ``verdict`` (plus ``reason``,
    ``correction``, ``seconds``). The computation may raise; the caller reports that as a
    failed item (:mod:`brdfkit.report.reproduce`)."""
    t0 = time.perf_counter()
    numbers = json_ready(claim.compute(ctx))
    out = claim.rule(numbers, claim.tolerance)
    if out.verdict not in VERDICTS:
        raise ValueError(f"claim {claim.id}: its rule returned {out.verdict!r}; a verdict is "
                         f"one of {', '.join(VERDICTS)}")
    return {"id": claim.id, "paper": claim.paper, "section": claim.section,
            "location": claim.location, "statement": claim.statement,
            "method": claim.method, "tolerance": claim.tolerance,
            "verdict": out.verdict, "reason": out.reason, "correction": out.correction,
            "numbers": numbers, "seconds": time.perf_counter() - t0}
