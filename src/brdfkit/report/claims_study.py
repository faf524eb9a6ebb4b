"""
Claims tested on the fitting study's batches (Neumann §1.1, §3/§6; Nielsen's fits)
==================================================================================

The fitting study (:mod:`brdfkit.fitting.study`) fits every MERL material; its verdicts
are computed by :mod:`brdfkit.report.fit_study_verdicts` from the batch files (the
shipped ones under ``docs/fitting-study-data/`` by default, re-scored, not refitted; a
``--full`` run's own). :func:`study_claim` makes a claim record of one of them, so the
report and ``docs/fitting-study.md`` read the same verdicts. The study's words map onto
the report's verdicts: "supported" → confirmed, "not supported" and "partly supported"
(the paper's claim is general; it holds on part of the materials only) → refuted, "no
data" → undetermined.
"""

from __future__ import annotations

import os

from brdfkit.report.claim_record import Claim, Outcome

__all__ = ["STUDY_CLAIMS", "STUDY_VERDICT", "ledger_id", "read_shipped_study", "study_claim",
           "study_rows"]

#: The study's verdict words → the report's verdicts.
STUDY_VERDICT = {"supported": "confirmed", "not supported": "refuted",
                 "partly supported": "refuted", "no data": "undetermined"}


#: The claims ledger's id of each study verdict → the words its claim (or test) contains.
STUDY_CLAIMS = {
    "neumann-1.1-perceptual": "perceptual fitting",
    "neumann-3-pumped-fit-g1": "pumped Phong (g₁ = max) fit",
    "neumann-3-pumped-fit-g2": "pumped Phong (g₂ = controlled) fit",
    "nielsen-both-kinds": "some materials are fitted best",
    "nielsen-alpha-mix-better": "fits better to a broader range",
    "nielsen-l1-l2": "L2 fits the lobe to the tops",
    "nielsen-robust": "robust convergence",
}


def _text(row: dict) -> str:
    return row["claim"] + " | " + row["test"]


def ledger_id(row: dict) -> str:
    """The ledger's claim id of a study verdict (a row of ``fit_study_verdicts.claims``),
    or ``""`` when the ledger has none (the Ngan anchors: not a claim of the papers)."""
    for cid, match in STUDY_CLAIMS.items():
        if match in _text(row):
            return cid
    return ""


def read_shipped_study(directory: str) -> dict:
    """The batches under *directory* (:func:`brdfkit.fitting.study.read_study`); an error
    naming the directory when it holds none."""
    from brdfkit.errors import BrdfkitError
    from brdfkit.fitting.study import read_study

    if not os.path.isdir(directory):
        raise BrdfkitError(f"the fitting study's batch directory {directory!r} does not exist "
                           "(the shipped batches are docs/fitting-study-data/ of a clone)")
    study = read_study(directory)
    if not study:
        raise BrdfkitError(f"no fitting-study batch files under {directory!r}")
    return study


def study_rows(ctx) -> list[dict]:
    """Every verdict of :func:`brdfkit.report.fit_study_verdicts.claims` on the study."""
    from brdfkit.report.fit_study_verdicts import claims

    return claims(read_shipped_study(ctx.study_dir))


def study_claim(*, id: str, paper: str, location: str, section: str,
                statement: str) -> Claim:
    """A claim record whose numbers are the study verdict :data:`STUDY_CLAIMS` names for
    *id*."""
    match = STUDY_CLAIMS[id]

    def compute(ctx):
        rows = [r for r in study_rows(ctx) if match in _text(r)]
        if not rows:
            return {"study_verdict": "no data", "evidence": "", "test": ""}
        r = rows[0]
        return {"study_verdict": r["verdict"], "evidence": r["evidence"], "test": r["test"],
                "study_claim": r["claim"]}

    def rule(numbers, tol):
        v = numbers["study_verdict"]
        reason = (f"the study says {v}: {numbers['evidence']}" if numbers["evidence"] else
                  "the study's batches hold no fits for this claim")
        return Outcome(STUDY_VERDICT[v], reason)

    return Claim(id, paper, location, statement,
                 "fitting study (brdfkit.fitting.study; verdict by brdfkit.report."
                 "fit_study_verdicts): the test is in the numbers' 'test'.",
                 compute, rule, None, section)
