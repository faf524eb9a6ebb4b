"""
The convergence record of a fit: typed stage, start and bound records
=====================================================================

:class:`Convergence` is ``FitResult.convergence``: what every stage did
(:class:`StageRecord`), every run of the shape search (:class:`StartRecord`), the
coordinates at a bound (:class:`AtBound`) and what the fit held or found on the way.
``to_dict()`` gives the JSON of ``FitResult.to_dict()["convergence"]`` (the keys and
values the command line's ``--json`` has always printed, optional ones only where they
apply, in a fixed order); the record also reads like that dict (``conv["stages"]``,
``conv.get("surrogate")``) for code written against it.

Public objects
--------------
- :class:`Convergence`, :class:`StageRecord`, :class:`StartRecord`, :class:`AtBound`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

__all__ = ["Convergence", "StageRecord", "StartRecord", "AtBound"]


class _Record:
    """Base of the records: ``to_dict`` over the dataclass fields."""


def _plain(v):
    """*v* with records turned into their dicts (recursively, in lists and dicts)."""
    if isinstance(v, _Record):
        return v.to_dict()
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_plain(x) for x in v]
    return v


@dataclass
class StageRecord(_Record):
    """One stage: its name, the coordinates it moved, its evaluations, the loss before
    and after, whether it hit its evaluation budget, the coordinates at a bound after."""

    stage: str
    parameters: list
    evaluations: int
    loss_before: float
    loss_after: float
    hit_limit: bool
    at_bounds: list

    def to_dict(self) -> dict:
        return {"stage": self.stage, "parameters": self.parameters,
                "evaluations": self.evaluations, "loss_before": self.loss_before,
                "loss_after": self.loss_after, "hit_limit": self.hit_limit,
                "at_bounds": self.at_bounds}


@dataclass
class StartRecord(_Record):
    """One run of the shape search: its start's label, the free parameters at its start
    and end, the loss at the end (on the fit's samples, linear parameters re-solved) and
    on the search's samples, evaluations, whether it hit its budget; or ``skipped`` (why
    it did not run)."""

    start: str
    start_values: dict | None = None
    end_values: dict | None = None
    loss: float | None = None
    loss_search: float | None = None
    evaluations: int = 0
    hit_limit: bool = False
    skipped: str | None = None

    def to_dict(self) -> dict:
        if self.skipped is not None:
            return {"start": self.start, "skipped": self.skipped}
        return {"start": self.start, "from": self.start_values, "to": self.end_values,
                "loss": self.loss, "loss_search": self.loss_search,
                "evaluations": self.evaluations, "hit_limit": self.hit_limit}


@dataclass
class AtBound(_Record):
    """A coordinate at a bound of its declared range (``value``), or — with
    ``loss_change_at_bound`` — one the loss cannot tell from it (moved there the loss
    changes by that relative amount)."""

    parameter: str
    bound: str
    value: float
    fitted: float
    loss_change_at_bound: float | None = None

    def to_dict(self) -> dict:
        d = {"parameter": self.parameter, "bound": self.bound, "value": self.value,
             "fitted": self.fitted}
        if self.loss_change_at_bound is not None:
            d["loss_change_at_bound"] = self.loss_change_at_bound
        return d


#: Fields of Convergence emitted only when set (not None).
_OPTIONAL = frozenset({"gauge_held", "width_scan", "scale_held", "root_fit", "nested",
                       "bound_fits", "surrogate"})


@dataclass
class Convergence(_Record, Mapping):
    """The convergence record of one fit (module docstring). Field order is the JSON's."""

    procedure: str
    loss: str
    seed: int
    n_samples: int
    n_samples_search: int
    stages: list = field(default_factory=list)      # of StageRecord
    starts: list = field(default_factory=list)      # of StartRecord
    gauge_held: dict | None = None                  # label → value held (BRDF.fit_gauge)
    measured_half_width_deg: float | None = None    # the target's specular half-width
    inert: list = field(default_factory=list)       # parameters that change nothing
    linear: list = field(default_factory=list)      # solved in closed form
    static_bases: list = field(default_factory=list)  # bases evaluated once
    width_scan: list | None = None                  # first guesses of the width tried
    scale_held: list | None = None                  # a common scale a pumped model ignores
    root_fit: dict | None = None                    # the derived model's base fitted first
    nested: dict | None = None                      # the model without optional parameters
    bound_fits: dict | None = None                  # sub-models at bounds fitted first
    evaluations_search: int = 0                     # evaluations on the search's samples
    surrogate: dict | None = None                   # the stand-in evaluated during the fit
    evaluations: int = 0
    refused: int = 0                                # parameter sets the model refused
    time_s: float = 0.0
    at_bounds: list = field(default_factory=list)   # of AtBound

    def to_dict(self) -> dict:
        out = {}
        for name in self.__dataclass_fields__:
            v = getattr(self, name)
            if name in _OPTIONAL and v is None:
                continue
            out[name] = _plain(v)
        return out

    # read like the dict it replaces
    def __getitem__(self, key):
        return self.to_dict()[key]

    def __iter__(self):
        return iter(self.to_dict())

    def __len__(self) -> int:
        return len(self.to_dict())
