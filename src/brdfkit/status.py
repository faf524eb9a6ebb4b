"""
One status contract for every result
====================================

Every numerical result of brdfkit says how good it is the same way, SciPy style
(``scipy.integrate.quad_vec``'s ``status``/``success``/``message``):

- ``status`` — an integer code of the result's kind, 0 meaning "met its goal";
- ``success`` — whether the result may be used as stated (a code's ``success``);
- ``message`` — one line saying what the code means for *this* result, with numbers.

The codes of every kind are declared here, in one place, by :class:`Outcome` records
collected in a :class:`StatusCodes` table per kind (:data:`STATUS`). The numeric codes of
the kinds that existed before this module (albedo, fit) are kept, so saved batch files and
the command line's JSON keep their meaning; the *names* form one vocabulary across kinds:

==================  ===========================================================
name                meaning, in every kind that has it
==================  ===========================================================
``converged``       the stated goal (tolerance, significance, sample budget) is met
``limit``           an iteration or refinement limit stopped it first; the
                    estimate and its (larger) error are returned
``node_cap``        the next refinement would exceed a memory bound; as ``limit``
``at_bound``        converged, with parameters at a bound of their declared range
``nonfinite``       NaN or inf where a number was due; no estimate
``undetermined``    the computation cannot support a verdict either way
``rejected``        a statistical test rejected its null hypothesis (χ²)
==================  ===========================================================

Public objects
--------------
- :class:`Outcome` — one code: number, name, message, success.
- :class:`StatusCodes` — the codes of one kind of result.
- :data:`STATUS` — kind → :class:`StatusCodes` (``albedo``, ``fit``, ``verdict``,
  ``chi2``, ``render``, ``hemispherical``).
- :func:`status_codes` — the dispatcher, whose error lists the kinds.
- :func:`worst` — the status of several results together.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from brdfkit.errors import BrdfkitError

__all__ = ["Outcome", "StatusCodes", "STATUS", "status_codes", "worst", "NAMES"]

#: The shared vocabulary (module docstring).
NAMES = ("converged", "limit", "node_cap", "at_bound", "nonfinite", "undetermined",
         "rejected")


@dataclass(frozen=True)
class Outcome:
    """One status code of one kind of result."""

    code: int
    name: str
    message: str
    success: bool

    def __post_init__(self):
        if self.name not in NAMES:
            raise ValueError(f"status name {self.name!r} is not in the vocabulary {NAMES}")


class StatusCodes:
    """The codes of one kind of result, by number and by name.

    ``codes[1]`` and ``codes["limit"]`` return the :class:`Outcome`; ``codes.LIMIT`` its
    number (upper-case names as attributes, for code that compares statuses).
    """

    def __init__(self, kind: str, outcomes: Iterable[Outcome]):
        self.kind = kind
        self._by_code: dict[int, Outcome] = {}
        self._by_name: dict[str, Outcome] = {}
        for o in outcomes:
            if o.code in self._by_code or o.name in self._by_name:
                raise ValueError(f"{kind}: status {o.code}/{o.name!r} declared twice")
            self._by_code[o.code] = o
            self._by_name[o.name] = o
        if 0 not in self._by_code or self._by_code[0].name != "converged":
            raise ValueError(f"{kind}: code 0 must be 'converged'")

    def __getitem__(self, key: int | str) -> Outcome:
        table = self._by_name if isinstance(key, str) else self._by_code
        try:
            return table[key if isinstance(key, str) else int(key)]
        except KeyError:
            valid = ", ".join(f"{o.code} ({o.name})" for o in self)
            raise BrdfkitError(f"{self.kind}: no status {key!r}; the codes are {valid}") \
                from None

    def __getattr__(self, upper: str) -> int:
        # only upper-case names reach here (ordinary attributes are found first)
        if upper.isupper() and upper.lower() in self.__dict__.get("_by_name", {}):
            return self._by_name[upper.lower()].code
        raise AttributeError(upper)

    def __iter__(self):
        return iter(sorted(self._by_code.values(), key=lambda o: o.code))

    def __contains__(self, code) -> bool:
        return int(code) in self._by_code

    @property
    def messages(self) -> dict[int, str]:
        """code → message (the form the old ``STATUS_MESSAGES`` dicts had)."""
        return {o.code: o.message for o in self}

    def success(self, code: int) -> bool:
        return self[code].success

    def message(self, code: int) -> str:
        return self[code].message

    def describe(self, code: int, *details: str) -> str:
        """A result's one-line ``message``: *code*'s message, then what this result
        adds (its numbers, what did not converge), ``"; "``-joined; empty parts dropped."""
        said = "; ".join(d for d in details if d)
        return f"{self.message(code)}: {said}" if said else self.message(code)

    def __repr__(self) -> str:
        return f"StatusCodes({self.kind!r}, {[o.name for o in self]})"


def _o(code, name, message, success):
    return Outcome(code, name, message, success)


#: kind → its status codes. Codes of ``albedo`` and ``fit`` are the ones their results and
#: saved files have always used.
STATUS: dict[str, StatusCodes] = {
    "albedo": StatusCodes("albedo", [
        _o(0, "converged", "converged: the error estimate meets the tolerance", True),
        _o(1, "limit", "tolerance not reached after the last refinement level (the error "
                       "estimate is returned; a sharper lobe or a kink the model does not "
                       "declare)", False),
        _o(2, "node_cap", "tolerance not reached: the next refinement needs more nodes than "
                          "the memory bound allows (the error estimate is returned)", False),
        _o(3, "nonfinite", "the integrand is NaN or infinite at some quadrature nodes "
                           "(albedo NaN)", False),
    ]),
    "fit": StatusCodes("fit", [
        _o(0, "converged", "converged", True),
        _o(1, "at_bound", "converged with parameters at a bound of their declared range",
           True),
        _o(2, "limit", "evaluation limit reached before the tolerance", True),
        _o(3, "nonfinite", "the fitted model is not finite on the samples", False),
    ]),
    "verdict": StatusCodes("verdict", [
        _o(0, "converged", "every part of the verdict is supported by its accuracy", True),
        _o(1, "undetermined", "a part of the verdict is undetermined: its accuracy cannot "
                              "support either answer", True),
        _o(3, "nonfinite", "the model is NaN or infinite where the verdict evaluates it",
           False),
    ]),
    "chi2": StatusCodes("chi2", [
        _o(0, "converged", "the sampler follows its pdf (chi-squared test passed)", True),
        _o(1, "rejected", "chi-squared test rejected: the sampler does not follow its pdf",
           False),
        # success: the test passed; only the expected counts of a few cells are less exact
        _o(2, "limit", "the chi-squared test passed, but the pdf's integral did not reach "
                       "its tolerance in some cells", True),
        _o(3, "nonfinite", "the pdf or the samples are NaN or infinite", False),
    ]),
    "render": StatusCodes("render", [
        _o(0, "converged", "every term is within its stated error", True),
        _o(1, "limit", "a term did not reach its accuracy goal (its error estimate is "
                       "returned)", False),
        _o(2, "undetermined", "one Monte-Carlo pass: no standard error can be estimated "
                              "(render two or more passes)", False),
        _o(3, "nonfinite", "NaN or infinite radiance", False),
    ]),
    "hemispherical": StatusCodes("hemispherical", [
        _o(0, "converged", "converged: every directional albedo met its tolerance and the "
                           "outer rule's error estimate is stated", True),
        _o(1, "limit", "a directional albedo did not converge (refinement limit or node "
                       "cap; error estimate inf)", False),
        _o(3, "nonfinite", "a directional albedo is NaN", False),
    ]),
}


def status_codes(kind: str) -> StatusCodes:
    """The :class:`StatusCodes` of *kind*; the error lists the kinds."""
    try:
        return STATUS[kind]
    except KeyError:
        raise BrdfkitError(f"no result kind {kind!r}; the kinds are "
                           f"{', '.join(sorted(STATUS))}") from None


def worst(kind: str, codes: Iterable[int]) -> int:
    """The status of several results of one *kind* together: the largest failing code if
    any fails, else the largest code, else 0 (converged)."""
    table = status_codes(kind)
    codes = sorted({int(c) for c in codes})
    failing = [c for c in codes if not table.success(c)]
    if failing:
        return failing[-1]
    return codes[-1] if codes else 0
