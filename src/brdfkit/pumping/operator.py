"""
The pumping operator and the pumped model
=========================================

:func:`pump` divides a reciprocal, isotropic model by g (Neumann et al. 1999,
eq. 16), g₁ (eq. 20), g₂ (eq. 21) or a user g held to eq. (17), up to
:data:`MAX_TIMES` times; :class:`PumpedBRDF` is the result, a
:class:`~brdfkit.models.DerivedBRDF` built through the one constructor path of
derived models. Theory and evaluation: ``docs/pumping.md``.

Public objects
--------------
- :func:`pump`, :func:`pump_sequence`, :func:`from_dict`, :func:`mirror_radiance`.
- :class:`PumpedBRDF`, :class:`PumpingWarning`.
- :data:`G_CHOICES`, :data:`MAX_TIMES`, :data:`CHAIN_DIP_TOL`, :data:`G_FLOOR`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

from brdfkit._array import as_directions
from brdfkit._dual import Formulas
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF, DerivedBRDF
from brdfkit.pumping.kernels import G_NUMPY, chain_kernel, pumped_formula, stage_kernel
from brdfkit.pumping.table import ENGINE_ERR, _crossings, _dips, build_albedo_table
from brdfkit.tables import _as_2d, build_lookup, mu_of_w

__all__ = [
    "CHAIN_DIP_TOL",
    "G_CHOICES",
    "G_FLOOR",
    "MAX_TIMES",
    "PumpedBRDF",
    "PumpingWarning",
    "from_dict",
    "mirror_radiance",
    "pump",
    "pump_sequence",
]

#: Built-in correction terms: name → (code used by the kernel, equation).
G_CHOICES = {"max": 0, "controlled": 1}
_G_ALIASES = {"g1": "max", "g_1": "max", "max": "max", "controlled": "controlled",
              "g2": "controlled", "g_2": "controlled"}
_G_EQ = {"max": "eq. (20) g1 = max(a(L), a(V))",
         "controlled": "eq. (21) g2 = max(a(L), a(V), N.V, N.L)"}


#: A stage joins a chain (one lookup for all stages) when its tabulated albedo is
#: non-decreasing in cos θ up to dips this small (g is raised by the dip, so it only
#: grows: a rounding ripple of the table at normal incidence, ~1e-9, not a real
#: minimum such as a Fresnel rise at grazing, ~1e-2; small enough to keep the total
#: error of g within 1e-5).
CHAIN_DIP_TOL = 1e-6
#: g is never smaller than this: a zero albedo with f > 0 can only come from
#: rounding at the horizon, and dividing by it would give inf.
G_FLOOR = 1e-12

#: Most pumpings of one model (``times`` plus the stages it already has). Each stage
#: tabulates the albedo of the stage below it with the albedo engine, whose integrand
#: runs every stage below and has more kinks with every stage, so the cost grows much
#: faster than the number of stages. Measured (2 cores, ``brdfkit eval modified-phong
#: --pump controlled --times K``, default parameters, building the stages): K = 1, 2:
#: under 1 s each; K = 3: 6 s; K = 4: 36 s (2.5 min on a loaded machine); K = 5: 155 s.
#: (``--pump max`` of the same model stays one lookup per pair, a few seconds up to
#: K = 6, but the bound is one for every g and every model.) More has little visible
#: effect anyway: the gains of rho_hh of the n = 20 Phong after 1-4 controlled pumpings
#: are 0.234, 0.072, 0.017, 0.005 (``docs/pumping.md``). The CLI's ``--times`` and the
#: explorer have the same bound.
MAX_TIMES = 4


class PumpingWarning(UserWarning):
    """A pumping step cannot meet eq. (17) (the base gains energy somewhere)."""



# --------------------------------------------------------------------------- the model
class PumpedBRDF(DerivedBRDF):
    """f*(L, V) = f(L, V)/g(L, V): one pumping stage over a base model.

    Built by :func:`pump`; a :class:`~brdfkit.models.DerivedBRDF`, so a model
    like any other (its tables and lookups are built first, then the shared
    set-up validates the root's parameters and packs the kernel's rows).
    It declares the base's ``albedo_kinks`` (f/g has f's kinks) and its own
    ``albedo_kink_mus`` and :meth:`albedo_kinks_nv`. The base's parameters pass
    through (:attr:`values`, :meth:`with_params` re-pumps with new values),
    :meth:`sample` and :meth:`pdf` are the base's (the pumped lobe has the same
    shape, only reweighted by 1/g ∈ [1, 1/a]), :meth:`lobes` are the base's.

    Attributes
    ----------
    base : BRDF
        The model this stage divides (itself possibly pumped).
    root : BRDF
        The original, unpumped model.
    g : str
        ``"max"``, ``"controlled"`` or ``"custom"``.
    table : AlbedoTable
        The base's tabulated albedo.
    capped : bool
        Whether g is capped at 1 (False only for a base that gains energy).
    stages : list of str
        The g of every stage, innermost first.
    depth : int
        ``len(stages)``.
    chained : bool
        Whether this stage and all below it have non-decreasing albedos, so
        the kernel is f_root · q(max(N·L, N·V)) with one lookup
        (``docs/pumping.md``, "Evaluation"); otherwise the kernel wraps the
        base's with two lookups of this stage's albedo.
    lookups : tuple of Lookup
        Per channel: q of the chain (``chained``) or this stage's capped
        albedo; empty for a custom g (evaluated in NumPy from ``table``).
    """

    @property
    def fit_base(self) -> BRDF:
        """A fit starts from the unpumped root's fit (``BRDF.fit_base``)."""
        return self.root

    def __init__(self, base: BRDF, g: str | Callable = "max", *, table=None):
        # table: the base's AlbedoTable when built otherwise (a draft's: brdfkit.pumping.draft)
        self.base = base
        self.root = base.root if isinstance(base, PumpedBRDF) else base
        self.g = g if isinstance(g, str) else "custom"
        self._g_callable = None if isinstance(g, str) else g
        self.stages = (base.stages if isinstance(base, PumpedBRDF) else []) + [self.g]
        self.depth = len(self.stages)
        self._n_rows = base.packed.shape[0]  # 1, or the number of channels
        self.table = build_albedo_table(base) if table is None else table
        self.capped = bool(np.all(self.table.max_albedo - self.table.max_midpoint_error
                                  <= 1.0 + ENGINE_ERR))
        if not self.capped:
            if self._g_callable is not None:
                raise ParameterError(
                    f"pump: the albedo of {base.name} reaches {self.table.max_albedo.max():.6g} "
                    "> 1, so no g can satisfy eq. (17) max(a(L), a(V)) <= g <= 1; use "
                    "g='max', which drops the cap g <= 1 and still gives a* <= 1")
            warnings.warn(
                f"pump: the albedo of {base.name} exceeds 1 (max {self.table.max_albedo.max():.4g})"
                "; eq. (17) cannot hold there, so g is not capped at 1: a* <= 1 everywhere, but "
                "a* < a where a > 1", PumpingWarning, stacklevel=3)
        if self._g_callable is not None:
            _validate_g(self._g_callable, self._albedo_at_cos)
        kernel = self._build_kernel()
        root = self.root
        super().__init__(
            name=f"{root.name}+pump[{','.join(self.stages)}]",
            params=root.params, values=root.values,
            citation=(f"{root.citation}; pumped: Neumann et al. 1999 eq. (16) with "
                      + ", ".join(_G_EQ.get(s, "a user g (eq. 17)") for s in self.stages)),
            summary=f"{root.name} with its albedo pumped up ({', '.join(self.stages)})",
            reciprocal=True, has_sampler=base.has_sampler, width_param=root.width_param,
            mirror_symmetric=base.mirror_symmetric, kernel=kernel)
        self.albedo_kinks = base.albedo_kinks  # f/g has f's kinks (and g's: albedo_kinks_nv)
        self.albedo_kink_mus = self._kink_mus()

    def _build_kernel(self):
        """This stage's lookups and compiled kernel (None for a custom g or a base
        without a kernel: :meth:`eval` then works in NumPy). Sets ``lookups``,
        ``chained``, ``_chain``, ``_dip`` and ``_driver``."""
        base = self.base
        self.lookups: tuple = ()
        self.chained = False
        self._chain: tuple = ()
        self._driver = None
        if base.kernel is None or self._g_callable is not None:
            return None
        parent_chained = not isinstance(base, PumpedBRDF) or base.chained
        self._dip = _dips(self._albedo_at_cos)
        if parent_chained and np.all(self._dip <= CHAIN_DIP_TOL):
            # every stage so far has a non-decreasing albedo: the whole chain is
            # f_root · q(max(N·L, N·V)) with one lookup (see the class docstring)
            self.chained = True
            self._chain = (base._chain if isinstance(base, PumpedBRDF) else ()) + (self,)
            # one lookup per channel (each with its own grid and margin, so a coloured
            # model pumps exactly like its channels pumped one by one)
            self.lookups = tuple(
                build_lookup(lambda mu, c=c: self._chain_q(mu)[:, c:c + 1], bound="lower",
                             kinks=np.concatenate([s._divisor_kinks(c) for s in self._chain]))
                for c in range(self._n_rows))
            kernel, self._driver = chain_kernel(
                self.root.kernel, self.root.packed.shape[1],
                all(s.capped for s in self._chain))
        else:
            self.lookups = tuple(
                build_lookup(lambda mu, c=c: np.maximum(
                    _as_2d(self.table.at_cos(mu))[:, c:c + 1], G_FLOOR),
                    bound="upper", kinks=self._divisor_kinks(c, table_only=True))
                for c in range(self._n_rows))
            kernel, self._driver = stage_kernel(
                base.kernel, self.g == "controlled", self.capped, self.depth)
        return kernel

    def _kink_mus(self) -> tuple:
        """cos θ_L where this stage's albedo a*(θ_L) has a kink (for the next table).

        A branch switch of g that happens for every V at once as L moves makes a
        kink in a*(L): for g₂ where the tabulated a(L) crosses N·L = cos θ_L.
        Switches between a(L) and a(V) or N·V sweep over V smoothly and leave a*
        smooth. The base's kinks carry over (g uses a(L)).
        """
        out = list(self.base.albedo_kink_mus)
        if self.g == "controlled":
            grid = np.linspace(1e-6, 1.0, 2049)

            def diff(m):
                return _as_2d(self._albedo_at_cos(m)) - m[:, None]

            out += list(_crossings(diff, grid, diff(grid)))
        return tuple(sorted(set(round(float(m), 14) for m in out)))

    # ------------------------------------------------------- evaluation lookup
    def _divisor(self, mu) -> np.ndarray:
        """This stage's g as a function of μ = max(N·L, N·V), shape (T, C).

        The table plus its dip d (≤ CHAIN_DIP_TOL; 0 when non-decreasing), so that
        max(a(L), a(V)) ≤ g(max(N·L, N·V)), capped at 1 (eq. 17; each stage, as
        the definition — capping only the product would dent the next stage's
        albedo near normal incidence, where the tables, upper bounds, exceed 1 by
        their margin), raised to μ for g₂ (eq. 21), floored at G_FLOOR.
        """
        mu = np.asarray(mu, dtype=np.float64)
        g = _as_2d(self.table.at_cos(mu)) + self._dip
        if self.capped:
            g = np.minimum(g, 1.0)
        if self.g == "controlled":
            g = np.maximum(g, np.clip(mu, 0.0, 1.0)[:, None])
        return np.maximum(g, G_FLOOR)

    def _chain_q(self, mu) -> np.ndarray:
        """q(μ) = 1/∏ g_j(μ) over the chained stages, shape (T, C)."""
        q = 1.0 / self._chain[0]._divisor(mu)
        for stage in self._chain[1:]:
            q = q / stage._divisor(mu)
        return q

    def _divisor_kinks(self, c: int, table_only: bool = False) -> np.ndarray:
        """μ where channel *c* of this stage's g(μ) is not smooth: the table's piece
        boundaries and its end at THETA_TOP and, unless *table_only* (the albedo
        lookup of an unchained stage, capped in its kernel), where it reaches the
        cap 1 and (g₂) where it crosses μ."""
        w = self.table.breaks[:-1]
        out = [mu_of_w(w)]
        if table_only:
            return out[0]
        dip = float(self._dip[c])

        def a(m):  # as in _divisor
            return _as_2d(self.table.at_cos(m))[:, c:c + 1] + dip

        grid = np.linspace(0.0, 1.0, 4097)
        a_grid = a(grid)
        cap = 1.0 if self.capped else np.inf
        if self.capped:
            out.append(_crossings(lambda m: a(m) - 1.0, grid, a_grid - 1.0))
        if self.g == "controlled":
            out.append(_crossings(lambda m: np.minimum(a(m), cap) - m[:, None], grid,
                                  np.minimum(a_grid, cap) - grid[:, None]))
        return np.concatenate(out)

    # ---------------------------------------------------------------- packing
    def _pack(self) -> np.ndarray:
        """Packed rows for the kernel: root parameters, lookups, offsets trailer.

        Layout of channel c: the root's K parameters; the lookup of the last
        chained stage (at offset K, read by :func:`_chain_kernel`); the lookup
        of every later (unchained) stage; then a trailer of ``depth`` offsets,
        ``p[len(p) - d]`` = start of stage d's lookup (0 for chained stages),
        read by :func:`_stage_kernel`. Every nested kernel reads this one row.
        """
        if self.kernel is None:
            return self.base.packed  # not used by a kernel
        chain = []
        node = self
        while isinstance(node, PumpedBRDF):
            chain.append(node)
            node = node.base
        chain.reverse()  # stage 1 … depth
        root = self.root.packed
        last_chained = max((s for s in chain if s.chained), key=lambda s: s.depth, default=None)
        rows = []
        for c in range(root.shape[0]):
            parts = [root[c]]
            pos = root.shape[1]
            offsets = np.zeros(self.depth)
            for stage in chain:
                if stage.chained and stage is not last_chained:
                    continue  # superseded by the last chained stage's product lookup
                offsets[stage.depth - 1] = 0.0 if stage.chained else pos
                block = stage.lookups[c].packed(0)
                parts.append(block)
                pos += block.size
            rows.append((parts, offsets[::-1]))  # p[len(p) - d] is stage d's offset
        # channels' lookups differ in length: pad before the trailer
        width = max(sum(x.size for x in parts) for parts, _ in rows)
        return np.ascontiguousarray(np.array(
            [np.concatenate(parts + [np.zeros(width - sum(x.size for x in parts)), trailer])
             for parts, trailer in rows], dtype=np.float64))

    # -------------------------------------------------------------- evaluation
    def eval(self, wi, wo) -> np.ndarray:
        """Pumped BRDF f*(wi, wo) = f(wi, wo)/g(wi, wo) in 1/sr (see :meth:`BRDF.eval`)."""
        if self.kernel is not None:
            return super().eval(wi, wo)
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        f = np.asarray(self.base.eval(wi, wo))
        a_i = self._albedo_at_cos(wi[..., 2])
        a_o = self._albedo_at_cos(wo[..., 2])
        g_fn = self._g_callable if self._g_callable is not None else G_NUMPY[self.g]
        g = np.asarray(g_fn(wi, wo, a_i, a_o), dtype=np.float64)
        if self.capped:
            g = np.minimum(g, 1.0)
        g = np.maximum(g, G_FLOOR)  # see G_FLOOR
        return np.where(f > 0.0, f / np.where(f > 0.0, g, 1.0), 0.0)

    __call__ = eval

    def _albedo_at_cos(self, mu) -> np.ndarray:
        """Tabulated albedo (upper bound); capped at 1 for an energy-conserving base."""
        a = self.table.at_cos(mu)
        return np.minimum(a, 1.0) if self.capped else a

    def albedo_kinks_nv(self, theta) -> np.ndarray:
        """Levels k of N·V = cos θ_V where f*(L, ·) has a kink, for the albedo engine.

        g switches branch where two of its arguments are equal; all of them depend
        on V only through θ_V, so every kink is a circle N·V = k: a(V) = a(L)
        (k = cos θ_L and the other roots when a is not monotone), and for the
        controlled g₂ also N·V = a(L), a(V) = N·L and a(V) = N·V. Earlier stages'
        kinks are included. Returns shape (T, K), NaN where a level does not exist.
        """
        th = np.asarray(theta, dtype=np.float64).reshape(-1)
        mu_l = np.cos(th)
        grid = np.linspace(0.0, 1.0, 1025)  # cos θ_V; roots located to ~1e-3 then refined
        a_grid = _as_2d(self._albedo_at_cos(grid))  # (M, C)
        a_l = _as_2d(self._albedo_at_cos(mu_l))  # (T, C)
        cols: list[np.ndarray] = [mu_l]

        def roots(diff):  # diff (T, M): the crossings in cos θ_V by linear interpolation
            sgn = np.signbit(diff)
            out = []
            for r in range(diff.shape[0]):
                idx = np.nonzero(sgn[r, 1:] != sgn[r, :-1])[0][:3]
                row = np.full(3, np.nan)
                for q, j in enumerate(idx):
                    d0, d1 = diff[r, j], diff[r, j + 1]
                    row[q] = grid[j] + (grid[j + 1] - grid[j]) * d0 / (d0 - d1)
                out.append(row)
            return np.array(out).reshape(diff.shape[0], 3)

        for ch in range(a_grid.shape[1]):
            cols.append(roots(a_grid[None, :, ch] - a_l[:, ch:ch + 1]))
            if self.g == "controlled":
                cols.append(a_l[:, ch])
                cols.append(roots(a_grid[None, :, ch] - mu_l[:, None]))
                own = roots((a_grid[:, ch] - grid)[None, :])
                cols.append(np.broadcast_to(own, (th.size, own.shape[1])))
        below = self.base.albedo_kinks_nv(th)  # None: the base declares none
        if below is not None:
            cols.append(np.asarray(below, dtype=np.float64).reshape(th.size, -1))
        kv = np.column_stack([np.asarray(c, dtype=np.float64).reshape(th.size, -1)
                              for c in cols])
        kv = np.where((kv > 0.0) & (kv < 1.0), kv, np.nan)
        # distinct levels first (a root of a(V) = a(L) is usually cos θ_L itself)
        kv = np.sort(np.round(kv, 12), axis=1)
        dup = np.zeros_like(kv, dtype=bool)
        dup[:, 1:] = np.abs(np.diff(kv, axis=1)) < 1e-9
        kv = np.where(dup, np.nan, kv)
        return np.sort(kv, axis=1)  # NaNs last

    def formulas(self) -> Formulas | None:
        """The kernel as formulas when the root gives them (else None): eval composed from
        the root's eval formula (:func:`~brdfkit.pumping.kernels.pumped_formula`), the
        tables from the root's K columns on; the root's sampler and pdf (as :meth:`sample`)."""
        root = self.root.formulas()
        if root is None or self.kernel is None or root.tables is not None:
            return None
        return Formulas(eval=pumped_formula(self, root.eval), sample=root.sample,
                        pdf=root.pdf, args=root.args, tables=self.root.packed.shape[1],
                        vectorise=root.vectorise)

    def sample(self, wo, u):
        """The base model's sampler (the pdf is the base pdf)."""
        return self.base.sample(wo, u)

    def pdf(self, wi, wo):
        """The base model's pdf."""
        return self.base.pdf(wi, wo)

    def lobes(self):
        """The base model's lobes (f/g has the base's shape, reweighted by 1/g ∈ [1, 1/a])."""
        return self.base.lobes()

    # --------------------------------------------------------------- accessors
    def pump_chain(self) -> list[tuple[str | Callable, int]]:
        """The stages as run-length ``(g, times)`` pairs, innermost first."""
        chain: list = []
        node = self
        gs = []
        while isinstance(node, PumpedBRDF):
            gs.append(node._g_callable if node._g_callable is not None else node.g)
            node = node.base
        for g in reversed(gs):
            if chain and chain[-1][0] is g or (chain and isinstance(g, str) and chain[-1][0] == g):
                chain[-1] = (g, chain[-1][1] + 1)
            else:
                chain.append((g, 1))
        return chain

    def with_params(self, **changes) -> BRDF:
        """The same pumping applied to the root model with some parameters changed."""
        m = self.root.with_params(**changes)
        for g, k in self.pump_chain():
            m = pump(m, g, times=k)
        return m

    def to_dict(self) -> dict:
        """The root's dict plus ``"pump": {"g": ..., "times": k}`` (a list if stages differ)."""
        d = self.root.to_dict()
        chain = [{"g": g if isinstance(g, str) else "custom", "times": k}
                 for g, k in self.pump_chain()]
        d["pump"] = chain[0] if len(chain) == 1 else chain
        return d

    def __repr__(self) -> str:
        g = self.g if self._g_callable is None else self._g_callable
        return f"brdfkit.pumping.pump({self.base!r}, g={g!r}, times=1)"


def _validate_g(g: Callable, albedo_at_cos: Callable) -> None:
    """Check a user g against eq. (17) on a structured set of pairs; raise with a witness."""
    th = np.radians([0.0, 10.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9])
    dphi = np.radians([0.0, 45.0, 90.0, 135.0, 180.0])
    ti, to, dp = (x.ravel() for x in np.meshgrid(th, th, dphi, indexing="ij"))
    wi = np.stack([np.sin(ti), np.zeros_like(ti), np.cos(ti)], axis=-1)
    wo = np.stack([np.sin(to) * np.cos(dp), np.sin(to) * np.sin(dp), np.cos(to)], axis=-1)
    a_i = albedo_at_cos(wi[..., 2])
    a_o = albedo_at_cos(wo[..., 2])
    try:
        g_lv = np.asarray(g(wi, wo, a_i, a_o), dtype=np.float64)
        g_vl = np.asarray(g(wo, wi, a_o, a_i), dtype=np.float64)
        g_lv = np.broadcast_to(g_lv, np.broadcast_shapes(g_lv.shape, a_i.shape))
        g_vl = np.broadcast_to(g_vl, g_lv.shape)
    except BrdfkitError:
        raise
    except Exception as exc:  # a user callable can fail in any way; report it as bad input
        raise ParameterError(f"pump: the custom g(wi, wo, a_i, a_o) failed on arrays of "
                             f"shape {wi.shape}: {type(exc).__name__}: {exc}") from exc
    lower = np.maximum(a_i, a_o)
    checks = [
        ("g must be finite", ~np.isfinite(g_lv)),
        ("symmetry g(L, V) = g(V, L)", np.abs(g_lv - g_vl) > 1e-9 * np.maximum(1.0, np.abs(g_lv))),
        ("max(a(L), a(V)) <= g", g_lv < lower - 1e-9),
        ("g <= 1", g_lv > 1.0 + 1e-9),
    ]
    for what, bad in checks:
        if np.any(bad):
            idx = np.argwhere(bad)[0]
            j = int(idx[0])
            extra = (f", g(V, L) = {float(np.ravel(g_vl[j])[0]):.6g}" if "symmetry" in what
                     else f", max(a(L), a(V)) = {float(np.ravel(lower[j])[0]):.6g}")
            raise ParameterError(
                f"pump: the custom g violates eq. (17) ({what}): g(L, V) = "
                f"{float(np.ravel(g_lv[j])[0]):.6g}{extra} at L = (theta {math.degrees(ti[j]):g} "
                f"deg, phi 0 deg), V = (theta {math.degrees(to[j]):g} deg, phi "
                f"{math.degrees(dp[j]):g} deg)")


# --------------------------------------------------------------------------- operator
def pump(model: BRDF, g: str | Callable = "max", *, times: int = 1) -> BRDF:
    """Pump up the albedo of *model* (Neumann et al. 1999, eq. 16), *times* times.

    Parameters
    ----------
    model : BRDF
        A reciprocal model (``model.reciprocal`` true), registered or pumped.
    g : {"max", "controlled"} or callable
        ``"max"`` (also ``"g1"``): g₁ = max(a(L), a(V)), eq. (20);
        ``"controlled"`` (``"g2"``): g₂ = max(a(L), a(V), N·V, N·L), eq. (21).
        A callable ``g(wi, wo, a_i, a_o)`` (NumPy arrays; a_i, a_o are the
        tabulated albedos — upper bounds within 1e-5, capped at 1 for an
        energy-conserving base — with a trailing channel axis when coloured)
        must be symmetric with max(a_i, a_o) ≤ g ≤ 1 (eq. 17); it is checked
        on a structured set of pairs and evaluated in NumPy (slower).
    times : int, keyword-only
        Number of pumpings (≥ 0; 0 returns *model* itself); with the stages
        *model* already has, at most :data:`MAX_TIMES`.

    Returns
    -------
    BRDF
        A :class:`PumpedBRDF` (or *model* when ``times == 0``).

    Raises
    ------
    ParameterError
        Non-reciprocal or anisotropic base, unknown g, bad *times* (not an
        integer ≥ 0, or more than :data:`MAX_TIMES` stages in all), or a custom g that
        violates eq. (17) (the message names the condition and a pair).

    Warns
    -----
    PumpingWarning
        When the base's albedo exceeds 1 (eq. 17 cannot hold; see
        ``docs/pumping.md``, "Non-plausible bases").

    Examples
    --------
    >>> import brdfkit
    >>> from brdfkit.pumping import pump
    >>> m = pump(brdfkit.model("modified-phong", rho_d=0, rho_s=1, n=20), "controlled", times=2)
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"pump: model must be a brdfkit model (BRDF); got {type(model)!r}")
    _check_times("pump", model, times)
    if isinstance(g, str):
        key = g.strip().lower()
        if key not in _G_ALIASES:
            raise ParameterError(
                f"pump: g must be 'max' (g1, eq. 20), 'controlled' (g2, eq. 21) or a callable "
                f"g(wi, wo, a_i, a_o); got {g!r}")
        g = _G_ALIASES[key]
    elif not callable(g):
        raise ParameterError(f"pump: g must be a string or a callable; got {type(g)!r}")
    if not model.isotropic:
        raise ParameterError(
            f"pump: {model.name} is anisotropic; the pumping tables the albedo as a function "
            "of the incidence angle only, which needs an isotropic base")
    if not model.reciprocal:
        raise ParameterError(
            f"pump: {model.name} is not reciprocal (f(L, V) != f(V, L)); the pumped model "
            "f/g is reciprocal only for a symmetric base (Neumann et al. 1999 §3)")
    for _ in range(int(times)):
        model = PumpedBRDF(model, g)
    return model


def _check_times(fn: str, model: BRDF, times) -> None:
    """*times* must be an integer ≥ 0 with the model's stages at most MAX_TIMES in all."""
    if isinstance(times, bool) or not isinstance(times, int | np.integer) or times < 0:
        raise ParameterError(f"{fn}: times must be an integer >= 0; got {times!r}")
    done = model.depth if isinstance(model, PumpedBRDF) else 0
    if done + times > MAX_TIMES:
        already = (f" (the model already has {done} stage{'s' if done > 1 else ''})"
                   if done else "")
        raise ParameterError(
            f"{fn}: times must be at most MAX_TIMES = {MAX_TIMES} pumpings in all{already}; "
            f"got times = {int(times)}. Each stage tabulates the previous stage's albedo with "
            "the albedo engine, so the cost grows much faster than the stages (4 controlled "
            "pumpings of modified-phong take 1-2.5 min on 2 cores, 5 about 3), and more "
            "has little visible effect (the 4th pumping of the n = 20 Phong adds 0.005 to "
            "rho_hh)")


def pump_sequence(model: BRDF, g: str | Callable = "max", *, times: int = 3) -> list[BRDF]:
    """``[model, pumped once, …, pumped times]`` (each stage built once; *times* as in
    :func:`pump`)."""
    if not isinstance(model, BRDF):
        raise ParameterError(
            f"pump_sequence: model must be a brdfkit model (BRDF); got {type(model)!r}")
    _check_times("pump_sequence", model, times)
    out = [model]
    for _ in range(int(times)):
        out.append(pump(out[-1], g))
    return out


def mirror_radiance(model, theta) -> np.ndarray:
    """Output radiance toward the mirror direction under a point light, eq. (3).

    A point source of intensity 4π at distance 1 in direction L at incidence
    *theta* (radians, azimuth 0), viewer at R(L): L_out = f(L, R(L)) cos θ_L
    (Neumann et al. §1.1 normalise the irradiance to cos θ_L).
    Shape ``theta.shape`` (+ ``(C,)`` when coloured).
    """
    th = np.asarray(theta, dtype=np.float64)
    wi = np.stack([np.sin(th), np.zeros_like(th), np.cos(th)], axis=-1)
    wo = wi * np.array([-1.0, -1.0, 1.0])
    f = np.asarray(model.eval(wi, wo))
    cos = np.cos(th)
    return f * (cos[..., None] if f.ndim > th.ndim else cos)


def from_dict(d: dict) -> BRDF:
    """Rebuild a model from :meth:`BRDF.to_dict` / :meth:`PumpedBRDF.to_dict` output —
    a registered model or a material (``merl:…``), pumped or not — through
    :class:`brdfkit.spec.ModelSpec`."""
    from brdfkit.spec import ModelSpec

    return ModelSpec.from_dict(d).build()
