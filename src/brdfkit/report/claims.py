"""
The claims ledger: every claim of the three papers, one registry
================================================================

:data:`CLAIMS` maps a paper (``lewis``, ``neumann``, ``nielsen``) to its claim records
(:class:`~brdfkit.report.claim_record.Claim`), written in one module per paper:
:mod:`~brdfkit.report.claims_lewis`, :mod:`~brdfkit.report.claims_neumann`,
:mod:`~brdfkit.report.claims_nielsen` (the fitting claims through
:mod:`~brdfkit.report.claims_study`). :func:`claim` finds one by id. To add a claim,
add a record to its paper's tuple: the report, ``claims.json`` and the tests pick it up.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from brdfkit.errors import BrdfkitError
from brdfkit.report import claims_lewis, claims_neumann, claims_nielsen
from brdfkit.report.claim_record import Claim

__all__ = ["CLAIMS", "all_claims", "claim"]

#: paper → its claims, in the paper's order (read-only: edit the per-paper modules).
CLAIMS: Mapping[str, tuple[Claim, ...]] = MappingProxyType({
    "lewis": claims_lewis.CLAIMS,
    "neumann": claims_neumann.CLAIMS,
    "nielsen": claims_nielsen.CLAIMS,
})


def all_claims() -> list[Claim]:
    """Every claim, paper by paper."""
    return [c for cs in CLAIMS.values() for c in cs]


def claim(claim_id: str) -> Claim:
    """The claim with id *claim_id*, or BrdfkitError listing the ids."""
    for c in all_claims():
        if c.id == claim_id:
            return c
    raise BrdfkitError(f"unknown claim {claim_id!r}; claims: "
                       + ", ".join(c.id for c in all_claims()))
