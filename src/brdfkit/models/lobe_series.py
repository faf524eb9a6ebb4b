"""
Sums of lobes as formulas, unrolled for one model's number of lobes
===================================================================

``lafortune`` (Lafortune et al. 1997; Neumann et al. eq. 7) and ``nh-power-series``
(Lewis §7) sum a number of cosⁿ lobes that their parameters fix; their Numba kernels loop
over them. A formula (:mod:`brdfkit._dual`) has no loops, so the Mitsuba bridge's formulas
are *generated* for the instance's count m: the loop written out m times, the lobes'
parameters read from the packed row by constant index, as the NBRDF net is unrolled
(:mod:`brdfkit.data.surrogate_formulas`). One source per (model, m, the lobes'
:func:`~brdfkit.models._lobes.lobe_power` modes) is written to the drivers' cache
directory (:func:`brdfkit.models._drivers._load`), so Numba caches it on disk; the
parameter values are arguments, not literals (a new value compiles nothing).

- eval: the kernel's sum in the kernel's order, each term :func:`lobe_power` of the
  kernel's base (the same values as ``model.eval``, bit for bit where the kernel's
  ``lobe_pow`` and the formula's ``lobe_power`` agree: every mode);
- sample / pdf: the models' :class:`~brdfkit.models.sampling.Mixture` (the cosine, then
  one cosⁿ lobe per term: about the normalised (C_xy ω_ox, C_xy ω_oy, C_z ω_oz) for
  Lafortune, the N·H lobe through the half vector for the power series): the component
  picked from u₀ by the cumulative weights (the first whose sum exceeds u₀, a zero-weight
  pick replaced by the first largest weight, u₀ rescaled into it, as ``Mixture.sample``),
  then one direction drawn with the picked lobe's axis and exponent (selected: the lobes
  share one sampler, so one is evaluated, not m). Lafortune's weights depend on ω_o
  (its ``_strategy``: log ρ̄_d; log ρ̄_s + n log|a| + log(2π/(n+1)), or log ρ̄_s + log π
  for n = 0), normalised from their logarithms (:func:`~brdfkit.models.sampling.
  log_mixture_weights`: no overflow of |a|ⁿ); the series' are constants.

Public objects
--------------
- :func:`lafortune_formulas`, :func:`nh_series_formulas` — a model's ``Formulas``;
  :func:`series_eval` — its eval formula alone (what ``model.eval`` runs).
- :func:`mixture_pick_lines` — ``Mixture.sample``'s pick as generated formula lines
  (also the Kulla–Conty sampler's, :mod:`brdfkit.compensation.kernels`).
"""

from __future__ import annotations

import math

from brdfkit._cache import memo
from brdfkit._dual import Formulas
from brdfkit.models._lobes import lobe_mode

__all__ = ["lafortune_formulas", "nh_series_formulas", "series_eval", "mixture_pick_lines"]

_HEADER = '''"""brdfkit: generated {what} formulas, {m} lobes (models/lobe_series)."""
from brdfkit._dual import exp, formula, log, maximum, minimum, power, select, sqrt
from brdfkit.models._lobes import lobe_power, nh_dot
from brdfkit.models.sampling import axis_lobe, half_pdf_terms, malley

INV_PI = {inv_pi!r}
PI = {pi!r}
TWO_PI = {two_pi!r}
LOG_PI = {log_pi!r}
NEG_INF = -float("inf")
'''


def _chain(names: list[str], k: str = "k") -> str:
    """select(k == 0.0, names[0], select(k == 1.0, names[1], … names[-1])): the k-th name."""
    out = names[-1]
    for j in range(len(names) - 2, -1, -1):
        out = f"select({k} == {float(j)!r}, {names[j]}, {out})"
    return out


def mixture_pick_lines(weights: list[str]) -> list[str]:
    """Lines setting k (the picked component, a float) and ur (u₀ rescaled into it) from
    the normalised weights *weights* (names or expressions of the generated formula, which
    imports ``select``, ``minimum``, ``maximum``): ``Mixture.sample``'s pick, unrolled."""
    n = len(weights)
    lines = [f"    c0 = {weights[0]}"]
    lines += [f"    c{j} = c{j - 1} + {weights[j]}" for j in range(1, n)]
    count = " + ".join(f"select(c{j} <= u0, 1.0, 0.0)" for j in range(n))
    lines.append(f"    k = minimum({count}, {float(n - 1)!r})")
    lines.append(f"    wk = {_chain(weights)}")
    # the first largest weight (np.argmax), for a zero-weight pick
    lines.append(f"    top = 0.0\n    best = {weights[0]}")
    for j in range(1, n):
        lines.append(f"    top = select({weights[j]} > best, {float(j)!r}, top)\n"
                     f"    best = maximum(best, {weights[j]})")
    lines.append("    k = select(wk > 0.0, k, top)")
    lines.append(f"    wk = {_chain(weights)}")
    lines.append(f"    ck = {_chain([f'c{j}' for j in range(n)])}")
    # clipped to [0, 1] against rounding, as Mixture.sample
    lines.append("    ur = minimum(maximum((u0 - (ck - wk)) / select(wk > 0.0, wk, 1.0), 0.0),"
                 " 1.0)")
    return lines


# --------------------------------------------------------------------------- Lafortune
def _lafortune_source(m: int, modes: tuple, cache: bool) -> str:
    lobes = [f"x{j}, z{j}, n{j}" for j in range(m)]
    args = ", ".join(lobes)
    s = [_HEADER.format(what="lafortune", m=m, inv_pi=1.0 / math.pi, pi=math.pi,
                        two_pi=2.0 * math.pi,
                        log_pi=math.log(math.pi)),
         f"\n\n@formula(cache={cache})",
         "def lafortune_eval(ix, iy, iz, ox, oy, oz, p):",
         "    # packed row: rho_d, rho_s, m, C_xy[m], C_z[m], n[m] (Lafortune._pack_channel)",
         "    xy = ix * ox + iy * oy",
         "    zz = iz * oz",
         "    acc = 0.0"]
    for j in range(m):
        s.append(f"    acc = acc + lobe_power(p[{3 + j}] * xy + p[{3 + m + j}] * zz, "
                 f"p[{3 + 2 * m + j}], {modes[j]})")
    s.append("    return select((iz > 0.0) & (oz > 0.0), p[0] * INV_PI + p[1] * acc, 0.0)")
    # the weights' logarithms and the lobes' unit axes at wo
    s += [f"\n\n@formula(cache={cache})",
          f"def lafortune_weights(ox, oy, oz, log_d, log_s, {args}):",
          "    r2 = ox * ox + oy * oy"]
    for j in range(m):
        s += [f"    s{j} = sqrt((x{j} * x{j}) * r2 + (z{j} * oz) * (z{j} * oz))",
              f"    live{j} = s{j} > 0.0",
              # n = 0: the cosine's weight ∫ 1 cos dω = π; the other side's log(0) discarded
              f"    l{j} = select(n{j} == 0.0, log_s + LOG_PI, log_s + n{j} * log(s{j})"
              f" + log(TWO_PI / (n{j} + 1.0)))",
              f"    l{j} = select(live{j} | (n{j} == 0.0), l{j}, NEG_INF)"]
    logs = ["log_d"] + [f"l{j}" for j in range(m)]
    s.append(f"    top = maximum({logs[0]}, {logs[1]})")
    s += [f"    top = maximum(top, {g})" for g in logs[2:]]
    # every weight 0 (all logs −inf): the cosine alone (log_mixture_weights)
    s.append("    none = top == NEG_INF")
    s.append("    t = select(none, 0.0, top)")
    s.append("    e0 = select(none, 1.0, exp(log_d - t))")
    s += [f"    e{j + 1} = select(none, 0.0, exp(l{j} - t))" for j in range(m)]
    s.append("    total = " + " + ".join(f"e{j}" for j in range(m + 1)))
    out = [f"e{j} / total" for j in range(m + 1)]
    for j in range(m):
        # the unit axis; a zero axis (C_xy = C_z = 0) has weight 0: any axis, the normal
        out += [f"select(live{j}, x{j} * ox / select(live{j}, s{j}, 1.0), 0.0)",
                f"select(live{j}, x{j} * oy / select(live{j}, s{j}, 1.0), 0.0)",
                f"select(live{j}, z{j} * oz / select(live{j}, s{j}, 1.0), 1.0)"]
    s.append("    return (" + ", ".join(out) + ")")
    unpack = ", ".join([f"w{j}" for j in range(m + 1)]
                       + [f"a{j}{c}" for j in range(m) for c in "xyz"])
    call = f"lafortune_weights(ox, oy, oz, log_d, log_s, {args})"
    s += [f"\n\n@formula(cache={cache})",
          f"def lafortune_sample(ox, oy, oz, u0, u1, log_d, log_s, {args}):",
          f"    {unpack} = {call}"]
    s += mixture_pick_lines([f"w{j}" for j in range(m + 1)])
    # component k ≥ 1 is lobe k − 1; component 0 (and an exponent 0) the cosine
    ax = _chain(["0.0"] + [f"a{j}x" for j in range(m)])
    ay = _chain(["0.0"] + [f"a{j}y" for j in range(m)])
    az = _chain(["1.0"] + [f"a{j}z" for j in range(m)])
    nk = _chain(["0.0"] + [f"n{j}" for j in range(m)])
    s += ["    cx, cy, cz = malley(ur, u1)",
          f"    nk = {nk}",
          f"    lx, ly, lz = axis_lobe({ax}, {ay}, {az}, nk, ur, u1)",
          "    cos_ = nk == 0.0",
          "    return select(cos_, cx, lx), select(cos_, cy, ly), select(cos_, cz, lz)",
          f"\n\n@formula(cache={cache})",
          f"def lafortune_pdf(ix, iy, iz, ox, oy, oz, log_d, log_s, {args}):",
          f"    {unpack} = {call}",
          "    p_cos = maximum(iz, 0.0) / PI  # pdf_cosine_hemisphere's operations",
          "    p = w0 * p_cos"]
    for j in range(m):
        lobe = (f"(n{j} + 1.0) / TWO_PI * power(maximum(ix * a{j}x + iy * a{j}y + iz * a{j}z,"
                f" 0.0), n{j})")
        s.append(f"    p = p + w{j + 1} * select(n{j} == 0.0, p_cos, {lobe})")
    s.append("    return select(oz > 0.0, p, 0.0)\n")
    return "\n".join(s)


# --------------------------------------------------------------------------- N·H series
def _nh_source(m: int, modes: tuple, cache: bool) -> str:
    ws = ", ".join(f"w{j}" for j in range(m))
    ns = ", ".join(f"n{j}" for j in range(m))
    s = [_HEADER.format(what="nh-power-series", m=m, inv_pi=1.0 / math.pi, pi=math.pi,
                        two_pi=2.0 * math.pi, log_pi=math.log(math.pi)),
         f"\n\n@formula(cache={cache})",
         "def nh_series_eval(ix, iy, iz, ox, oy, oz, p):",
         "    # packed row: m, k[m], n[m] (NHPowerSeries._pack_channel)",
         "    nh, _ = nh_dot(ix, iy, iz, ox, oy, oz)",
         "    acc = 0.0"]
    s += [f"    acc = acc + p[{1 + j}] * lobe_power(nh, p[{1 + m + j}], {modes[j]})"
          for j in range(m)]
    s += ["    return select((iz > 0.0) & (oz > 0.0), acc, 0.0)",
          f"\n\n@formula(cache={cache})",
          f"def nh_series_sample(ox, oy, oz, u0, u1, {ws}, {ns}):"]
    s += mixture_pick_lines([f"w{j}" for j in range(m)])
    s += ["    cx, cy, cz = malley(ur, u1)",
          f"    nk = {_chain([f'n{j}' for j in range(m)])}",
          # h about the normal, ω_i its mirror (HalfVector(PowerHalf(n)))
          "    hx, hy, hz = axis_lobe(0.0, 0.0, 1.0, nk, ur, u1)",
          "    d = 2.0 * (ox * hx + oy * hy + oz * hz)",
          "    cos_ = nk == 0.0",
          "    return (select(cos_, cx, d * hx - ox), select(cos_, cy, d * hy - oy),",
          "            select(cos_, cz, d * hz - oz))",
          f"\n\n@formula(cache={cache})",
          f"def nh_series_pdf(ix, iy, iz, ox, oy, oz, {ws}, {ns}):",
          "    p_cos = maximum(iz, 0.0) / PI  # pdf_cosine_hemisphere's operations",
          "    hz, denom, ok = half_pdf_terms(ix, iy, iz, ox, oy, oz)",
          "    p = 0.0"]
    for j in range(m):
        half = (f"select(ok, (n{j} + 1.0) / TWO_PI * power(maximum(hz, 0.0), n{j}) / denom,"
                " 0.0)")
        s.append(f"    p = p + w{j} * select(n{j} == 0.0, p_cos, {half})")
    s.append("    return select(oz > 0.0, p, 0.0)\n")
    return "\n".join(s)


@memo(maxsize=32)  # one per (kind, lobe count, modes): a session uses a few
def _generated(kind: str, m: int, modes: tuple):
    """The generated module's (eval, sample, pdf) for *kind* with *m* lobes."""
    from brdfkit.models._drivers import _load

    source, names = {"lafortune": (_lafortune_source, "lafortune"),
                     "nh": (_nh_source, "nh_series")}[kind]
    module = _load(source(m, modes, cache=True))
    if module is None:  # an unwritable cache directory: compiled in memory
        module = {"__name__": f"brdfkit_generated_{names}_{m}"}
        exec(compile(source(m, modes, cache=False), f"<brdfkit {names} formulas>", "exec"),
             module)
        get = module.__getitem__
    else:
        get = module.__dict__.__getitem__
    return get(f"{names}_eval"), get(f"{names}_sample"), get(f"{names}_pdf")


def _modes(n) -> tuple:
    """Each lobe's :func:`lobe_power` mode by its exponent (a constant of the source)."""
    return tuple(lobe_mode(x) for x in n)


def _log(x: float) -> float:
    return math.log(x) if x > 0.0 else -math.inf


def series_eval(kind: str, n):
    """The eval formula of *kind* (``"lafortune"`` or ``"nh"``) for the lobes' exponents
    *n*: what ``model.eval`` runs, without the sampler's arguments of the full formulas."""
    return _generated(kind, len(n), _modes(n))[0]


def lafortune_formulas(model) -> Formulas:
    """A :class:`~brdfkit.models.lafortune.Lafortune`'s formulas (module docstring); the
    sampler's arguments log ρ̄_d, log ρ̄_s (channel means; −inf for 0) and per lobe
    (C_xy, C_z, n)."""
    import numpy as np

    v = model.channel_values(0)
    lobes = [float(x) for trio in zip(v["C_xy"], v["C_z"], v["n"], strict=True)
             for x in trio]
    ev, sample, pdf = _generated("lafortune", len(v["n"]), _modes(v["n"]))
    args = (_log(float(np.mean(model.values["rho_d"]))),
            _log(float(np.mean(model.values["rho_s"]))), *lobes)
    return Formulas(eval=ev, sample=sample, pdf=pdf, args=args)


def nh_series_formulas(model, weights) -> Formulas:
    """An :class:`~brdfkit.models.blinn.NHPowerSeries`'s formulas (module docstring) with
    its mixture *weights* (one per term)."""
    v = model.channel_values(0)
    ev, sample, pdf = _generated("nh", len(v["n"]), _modes(v["n"]))
    return Formulas(eval=ev, sample=sample, pdf=pdf,
                    args=(*(float(w) for w in weights), *(float(n) for n in v["n"])))
