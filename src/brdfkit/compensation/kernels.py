"""
The compiled kernels of compensated models
==========================================

A compensated model's kernel wraps its base's kernel with reads of the base's
tabulated white-form albedo Ẽ(μ) (:class:`brdfkit.tables.Lookup`), like the
pumped models' (:mod:`brdfkit.pumping.kernels`): each is generated with its own
compiled loop (:func:`brdfkit.models._drivers.composed`: the base kernel inlined, the
module cached on disk) and memoised per (base kernel, offset).

Packed row of one channel (``p``): the base's K parameters, then the channel's
constant at ``p[K]`` (Kulla–Conty: F_ms/(π(1 − E_avg)); Turquin: F₀), then the
lookup of Ẽ at ``p[K + 1:]`` (padded to the longest channel's): a single-level
:class:`~brdfkit.tables.UniformLookup` (4 reads) for a table of one smooth piece, else
the two-level :class:`~brdfkit.tables.Lookup` (8). The lookup is an upper bound of
min(E, 1) within its margin; the kernels clamp what they read at 1 (:func:`_e`), so
1 − Ẽ ≥ 0 and the compensated albedo 1 + E − Ẽ never exceeds 1 by the table's error
(``docs/compensation.md``).

- :func:`kulla_conty_kernel` — f_base + c (1 − Ẽ(μ_i))(1 − Ẽ(μ_o));
- :func:`turquin_kernel` — f_base (1 + F₀ (1 − Ẽ(μ_i))/Ẽ(μ_i));
- :func:`turquin_formula`, :func:`kulla_conty_formula` — the same as formulas
  (:mod:`brdfkit._dual`, the Mitsuba bridge's traced route) over the base's eval
  formula, Ẽ read with :func:`brdfkit.tables.lookup` / :func:`~brdfkit.tables.lookup_w`;
- :func:`kulla_conty_sampler`, :func:`kc_weight` — Kulla–Conty's sampler (the cosine and
  the base's sampler formulas, weighted by f_ms's share of the albedo at ω_o, with a
  polynomial for the channel mean of Ẽ(μ_o)) as formulas.

A base whose eval is a formula is composed from the ``_vector`` templates, which LLVM
vectorises with the table reads as gathers: every read a
:func:`brdfkit._kern.load_input`, all of them before the base's code
(``docs/architecture.md``, "Gathers in the vectorising loop").
"""

from __future__ import annotations

import math

import numba

from brdfkit._cache import memo
from brdfkit._dual import compose, formula, maximum, minimum, select
from brdfkit._kern import load_input, load_inputs
from brdfkit.models._drivers import VECTOR_OPTIONS, composed
from brdfkit.tables import _lookup, _lookup_w, lookup, lookup_w

__all__ = ["kulla_conty_formula", "kulla_conty_kernel", "kulla_conty_sampler", "kc_weight",
           "turquin_formula", "turquin_kernel"]

# The templates' globals, bound per composition (models/_drivers.composed): the base kernel,
# the compile-time offset of the channel's constant, and the read of Ẽ (_e_two_level or
# _e_uniform, as the table stores it).
base_kernel = None  # a kernel (ix, iy, iz, ox, oy, oz, p) -> float
k = 0
_e = None  # (p, off, mu) -> min(Ẽ(mu), 1)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _e_two_level(p, off, mu):  # pragma: no cover - compiled (inlined into the templates)
    e = _lookup(p, off, mu)
    return e if e < 1.0 else 1.0  # clamp (a select): the lookup's margin may exceed min(E, 1) = 1


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _e_uniform(p, off, mu):  # pragma: no cover - compiled (inlined into the templates)
    e = _lookup_w(p, off, mu)
    return e if e < 1.0 else 1.0  # clamp (a select), as _e_two_level


def _kulla_conty(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    # branch-free (a select), so that the "vector" loop vectorises it; _lookup clamps μ to
    # [0, 1], so the lanes below the horizon read in bounds and are discarded
    e_i = _e(p, k + 1, iz)
    e_o = _e(p, k + 1, oz)
    ms = p[k] * (1.0 - e_i) * (1.0 - e_o)
    return f + (ms if (iz > 0.0) & (oz > 0.0) else 0.0)


def _turquin(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    e_i = _e(p, k + 1, iz)  # >= E_FLOOR > 0 (brdfkit.compensation.table): no 0/0
    return f * (1.0 + p[k] * (1.0 - e_i) / e_i)


# The same for the vectorising loop ("vector", a base whose eval is a formula). Two things
# make LLVM vectorise it, with the table reads as gathers (each measured: without either the
# loop stays scalar; benchmarks/probe_vectorise_lookup.py, docs/compensation.md "Speed"):
# every read is a load_input (brdfkit._kern), the base's parameters passed to it as a tuple
# (load_inputs: a formula reads p[CONST], from a tuple as from an array), so that LLVM knows
# no read aliases the loop's store; and every read comes before the base's code (a read
# after it made the loop "not vectorized: call instruction cannot be vectorized").
def _kulla_conty_vector(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    q = load_inputs(p, k)
    c = load_input(p, k)
    e_i = _e(p, k + 1, iz)
    e_o = _e(p, k + 1, oz)
    f = base_kernel(ix, iy, iz, ox, oy, oz, q)  # 0 below the horizon
    ms = c * (1.0 - e_i) * (1.0 - e_o)
    return f + (ms if (iz > 0.0) & (oz > 0.0) else 0.0)


def _turquin_vector(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    q = load_inputs(p, k)
    f0 = load_input(p, k)
    e_i = _e(p, k + 1, iz)  # >= E_FLOOR > 0 (brdfkit.compensation.table): no 0/0
    f = base_kernel(ix, iy, iz, ox, oy, oz, q)  # 0 below the horizon
    return f * (1.0 + f0 * (1.0 - e_i) / e_i)


def _options(vector: bool) -> tuple[str, dict]:
    return ("vector", {"inline": "always", **VECTOR_OPTIONS}) if vector else ("checked", None)


def kulla_conty_kernel(base_kernel, k: int, *, vector: bool = False, uniform: bool = False):
    """(kernel, driver) of f_base + p[k] (1 − Ẽ(N·L))(1 − Ẽ(N·V)) (cached). *vector*: the
    base kernel is branch-free and total (a formula of :mod:`brdfkit._dual`), so the
    composition runs in the vectorising loop. *uniform*: Ẽ is a
    :class:`~brdfkit.tables.UniformLookup` (else a :class:`~brdfkit.tables.Lookup`)."""
    loop, options = _options(vector)
    template = _kulla_conty_vector if vector else _kulla_conty
    return composed(template, loop=loop, options=options, base_kernel=base_kernel, k=int(k),
                    _e=_e_uniform if uniform else _e_two_level)


def turquin_kernel(base_kernel, k: int, *, vector: bool = False, uniform: bool = False):
    """(kernel, driver) of f_base (1 + p[k] (1 − Ẽ(N·L))/Ẽ(N·L)) (cached); *vector* and
    *uniform* as :func:`kulla_conty_kernel`."""
    loop, options = _options(vector)
    template = _turquin_vector if vector else _turquin
    return composed(template, loop=loop, options=options, base_kernel=base_kernel, k=int(k),
                    _e=_e_uniform if uniform else _e_two_level)


# The formula template (brdfkit._dual.compose): base_eval an eval formula, read the
# primitive lookup or lookup_w (as the table stores Ẽ), k the constant's column.
base_eval = read = None


def _turquin_f(ix, iy, iz, ox, oy, oz, p):
    f = base_eval(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    e_i = minimum(read(p, k + 1, iz), 1.0)  # clamp, as _e_two_level; >= E_FLOOR > 0
    return f * (1.0 + p[k] * (1.0 - e_i) / e_i)


def turquin_formula(base_eval, k: int, *, uniform: bool = False):
    """:func:`turquin_kernel` as a formula over the base's eval formula (memoised); its
    table starts at column k + 1 (``Formulas.tables``)."""
    return compose(_turquin_f, base_eval=base_eval, k=int(k),
                   read=lookup_w if uniform else lookup)


# Kulla–Conty as formulas: eval over the base's eval formula, and the sampler of
# CompensatedBRDF._strategy (the cosine for f_ms and the base's sampler, weighted by f_ms's
# share of the albedo at ω_o) over the base's sampler formulas.
def _kulla_conty_f(ix, iy, iz, ox, oy, oz, p):
    f = base_eval(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    e_i = minimum(read(p, k + 1, iz), 1.0)  # clamp, as _e_two_level (reads clamp μ to [0, 1])
    e_o = minimum(read(p, k + 1, oz), 1.0)
    ms = p[k] * (1.0 - e_i) * (1.0 - e_o)
    return f + select((iz > 0.0) & (oz > 0.0), ms, 0.0)


def kulla_conty_formula(base_eval, k: int, *, uniform: bool = False):
    """:func:`kulla_conty_kernel` as a formula over the base's eval formula (memoised); its
    table starts at column k + 1 (``Formulas.tables``)."""
    return compose(_kulla_conty_f, base_eval=base_eval, k=int(k),
                   read=lookup_w if uniform else lookup)


#: Degree of the polynomial in x = 2μ − 1 that stands for the channel mean of Ẽ(μ_o) in the
#: sampler's weight (a sampler formula reads no table: its arguments are floats). The weight
#: only steers variance; 6 follows Ẽ of the rough microfacet bases to ~1e-3.
WEIGHT_DEGREE = 6
#: floor of the weight's denominator F̄_ms(1 − E) + F̄_avg E, 0 only where both vanish (no
#: 0/0); a float32 normal number, so that the guard holds in Mitsuba's single precision too
WEIGHT_FLOOR = 1e-30


@formula
def kc_weight(oz, fms, favg, q0, q1, q2, q3, q4, q5, q6):
    """f_ms's share of the compensated albedo at μ_o = oz, F̄_ms(1 − E)/(F̄_ms(1 − E) + F̄_avg E)
    (Kulla–Conty's sampling weight, channel means), E the polynomial q₀ + q₁x + … + q₆x⁶,
    x = 2μ_o − 1 (Horner); 0 for ω_o at or below the horizon."""
    x = 2.0 * oz - 1.0
    e = (((((q6 * x + q5) * x + q4) * x + q3) * x + q2) * x + q1) * x + q0
    e = minimum(maximum(e, 0.0), 1.0)  # clamp: a fit of an albedo in [0, 1] may overshoot it
    ms = fms * (1.0 - e)
    return select(oz > 0.0, ms / maximum(ms + favg * e, WEIGHT_FLOOR), 0.0)


_WEIGHT_ARGS = "fms, favg, q0, q1, q2, q3, q4, q5, q6"
_KC_SAMPLER = '''
def kc_sample(ox, oy, oz, u0, u1, {w}{b}):
    w = kc_weight(oz, {w})
    v = 1.0 - w
{pick}
    cx, cy, cz = malley(ur, u1)
    bx, by, bz = base_sample(ox, oy, oz, ur, u1{b})
    cos_ = k == 0.0
    return select(cos_, cx, bx), select(cos_, cy, by), select(cos_, cz, bz)


def kc_pdf(ix, iy, iz, ox, oy, oz, {w}{b}):
    w = kc_weight(oz, {w})
    p = w * (maximum(iz, 0.0) / PI) + (1.0 - w) * base_pdf(ix, iy, iz, ox, oy, oz{b})
    return select(oz > 0.0, p, 0.0)
'''


@memo(maxsize=16)  # one per arity of a base's sampler: a few
def _kc_sampler_templates(n_args: int) -> tuple:
    """The plain templates (kc_sample, kc_pdf) over a base sampler of *n_args* arguments
    (a formula has a fixed arity, and Numba inlines no call with ``*args``): source
    generated for that arity, base_sample and base_pdf bound by :func:`compose`."""
    from brdfkit.models.lobe_series import mixture_pick_lines
    from brdfkit.models.sampling import malley

    b = "".join(f", b{j}" for j in range(n_args))
    source = _KC_SAMPLER.format(w=_WEIGHT_ARGS, b=b,
                                pick="\n".join(mixture_pick_lines(["w", "v"])))
    ns = {"__name__": f"{__name__}.kc_sampler_{n_args}", "select": select,
          "minimum": minimum, "maximum": maximum, "malley": malley, "kc_weight": kc_weight,
          "PI": math.pi, "base_sample": None, "base_pdf": None}
    exec(compile(source, f"<brdfkit kulla-conty sampler, {n_args} arguments>", "exec"), ns)
    return ns["kc_sample"], ns["kc_pdf"]


def kulla_conty_sampler(base_sample, base_pdf, n_args: int) -> tuple:
    """(sample, pdf) formulas of the Kulla–Conty mixture over the base's sampler formulas;
    their arguments: F̄_ms, F̄_avg, the weight's 7 coefficients (:func:`kc_weight`), then
    the base's *n_args* arguments."""
    sample, pdf = _kc_sampler_templates(int(n_args))
    return (compose(sample, base_sample=base_sample),
            compose(pdf, base_pdf=base_pdf))
