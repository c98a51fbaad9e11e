"""The papers' values that calibration reads: one source for a fitted number.

A calibration claim (``role="calibration"``) declares the paper's value it was fitted to; code
that sets or checks a parameter from it reads that value here (:func:`claim_value`) instead of
repeating the digits, so the claim and the calibration cannot drift apart. Only calibration
claims can be read: a prediction's value must never reach the model (tests move every
prediction's value and check that no parameter moves).

This module and the claims files it reads (:mod:`.claims_file`) are plain data (the ``base``
layer, ``_layers.py``), so the laws (``plant/``) may import it.
"""

from __future__ import annotations

from fsarm_sim.studies.reproduce.claims import PAPERS, Claim, ClaimError
from fsarm_sim.studies.reproduce.claims_file import paper_claims


def find_claim(claim_id: str) -> Claim:
    """The declared claim ``claim_id`` (ClaimError naming it when there is none)."""
    for paper in PAPERS:
        for c in paper_claims(paper):
            if c.id == claim_id:
                return c
    raise ClaimError(f"no claim {claim_id!r} is declared (data/claims/*.toml)")


def claim_value(claim_id: str) -> float:
    """The paper's value of calibration claim ``claim_id`` (see the module docstring)."""
    c = find_claim(claim_id)
    if c.role != "calibration":
        raise ClaimError(
            f"{claim_id} is a {c.role} claim: only calibration claims may feed the model"
        )
    if c.paper_value is None:
        raise ClaimError(f"{claim_id} declares no paper_value to calibrate on")
    return float(c.paper_value)
