"""Every result says how good it is the same way: status, success, message (issue 18).

One parametrised test over every result type of brdfkit, each produced for real by a
small computation: a converged case and, where one can be provoked cheaply, the cases
that did not converge or failed. For each, the status is a code of its kind's table
(``brdfkit.status.STATUS``), ``success`` is that code's ``success`` and the message
contains that code's message. The expected code is the reference: it follows from the
construction of the case (stated beside it), not from the code under test — a NaN
integrand must be ``nonfinite``, an undeclared step integrated to 1e-12 cannot converge
in five halvings, a sampler whose pdf integrates to 1.25 is rejected.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import H_s, albedo, albedo_mc, check, hemispherical_albedo
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.analysis.energy_verdict import energy_verdict
from brdfkit.analysis.lewis_table2 import table2
from brdfkit.models import DerivedBRDF
from brdfkit.status import STATUS


# --------------------------------------------------------------------------- helpers
def _nan_callable(wi, wo):
    """NaN everywhere: no integral exists."""
    return np.full(np.broadcast_shapes(wi.shape, wo.shape)[:-1], np.nan)


def _step(wi, wo):
    """1/π where wo_x > 0.3: an undeclared discontinuity (tests/test_albedo_status.py)."""
    return np.where(wo[..., 0] > 0.3, 1.0 / math.pi, 0.0)


class _NaNModel(DerivedBRDF):
    """A model that is NaN wherever it is evaluated (evaluated in NumPy: kernel None)."""

    def eval(self, wi, wo):
        return _nan_callable(np.asarray(wi), np.asarray(wo))


def _nan_model():
    return _NaNModel(name="nan-model", params=(), values={}, reciprocal=True)


def _lambert_class():
    return type(brdfkit.model("lambert"))


def _overweighted():
    """Lambert with its cosine pdf scaled by 1.25 (sample() returns that pdf too): the pdf
    integrates to 1.25, which the χ² test must reject."""

    class Overweighted(_lambert_class()):
        def pdf(self, wi, wo):
            return 1.25 * super().pdf(wi, wo)

        def sample(self, wo, u):
            wi, _ = super().sample(wo, u)
            return wi, self.pdf(wi, np.broadcast_to(wo, np.shape(wi)))

    return Overweighted(rho_d=0.5)


def _nan_pdf():
    """Lambert whose pdf is NaN above 60° from the normal: not finite."""

    class NaNPdf(_lambert_class()):
        def pdf(self, wi, wo):
            p = super().pdf(wi, wo)
            return np.where(np.asarray(wi)[..., 2] < 0.5, np.nan, p)

        def sample(self, wo, u):
            wi, _ = super().sample(wo, u)
            return wi, self.pdf(wi, np.broadcast_to(wo, np.shape(wi)))

    return NaNPdf(rho_d=0.5)


def _verdict_undetermined(mp, verdict=check):
    # the node cap and no refinement: modified Phong with rho_s = 1, whose albedo at normal
    # incidence is 1 (Lewis eq. 16), cannot be certified to 1e-12 (as
    # tests/test_albedo_status.py::test_plausibility_undetermined_when_unconverged)
    import brdfkit.analysis.albedo_engine as eng

    mp.setattr(eng, "MAX_ANGLE_NODES", 2000)
    mp.setattr(eng, "MAX_LEVEL", 0)
    return verdict(brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=2000.0), tol=1e-12)


def _ambient_limit(mp):
    # a grid of at most 20 nodes cannot interpolate a sharp lobe's rho to 1e-9
    import brdfkit.render.ambient as amb

    mp.setattr(amb, "MAX_TABLE_NODES", 20)
    return amb.ambient_table(brdfkit.model("modified-phong", rho_d=0.1, rho_s=0.5, n=200.0),
                             theta_max=1.0, tol=1e-9)


def _render_limit(mp):
    import brdfkit.render.ambient as amb
    from brdfkit.render import render_sphere

    mp.setattr(amb, "MAX_TABLE_NODES", 20)
    return render_sphere(brdfkit.model("modified-phong", rho_d=0.1, rho_s=0.5, n=200.0),
                         phi_l=0.3, size=4, ambient=0.5, rho_tol=1e-9)


def _render(**kw):
    from brdfkit.render import render_sphere

    return render_sphere(**kw)


def _mitsuba(**kw):
    pytest.importorskip("mitsuba")
    return _render(**kw)


def _fit(model, target):
    from brdfkit.fitting import fit

    return fit(model, target, loss="l2")


# kind, expected code (by name), producer(monkeypatch) -> result
CASES = [
    # AlbedoResult: the engine
    ("albedo", "converged", lambda mp: albedo(brdfkit.model("lambert", rho_d=0.5),
                                              np.radians([0.0, 60.0]))),
    ("albedo", "limit", lambda mp: albedo(_step, 0.0, tol=1e-12)),
    ("albedo", "node_cap", lambda mp: (
        mp.setattr(__import__("brdfkit.analysis.albedo_engine", fromlist=["x"]),
                   "MAX_ANGLE_NODES", 5000),
        albedo(brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=5000.0),
               math.radians(30.0), tol=1e-14))[1]),
    ("albedo", "nonfinite", lambda mp: albedo(_nan_callable, [0.0, 0.5])),
    # AlbedoResult: the Monte-Carlo second method
    ("albedo", "converged", lambda mp: albedo_mc(brdfkit.model("lambert", rho_d=0.5), 0.3,
                                                 n_samples=1000, rng=1)),
    ("albedo", "nonfinite", lambda mp: albedo_mc(_nan_callable, 0.3, n_samples=100, rng=1)),
    # AlbedoResult: H_s (its goal includes 1e-10 relative, which its ~1e-11 quadrature
    # always meets: no failure to provoke)
    ("albedo", "converged", lambda mp: H_s(0.3, 20.0)),
    # HemisphericalAlbedo
    ("hemispherical", "converged",
     lambda mp: hemispherical_albedo(brdfkit.model("lambert", rho_d=0.6), n=8)),
    ("hemispherical", "limit", lambda mp: hemispherical_albedo(_step, n=2, tol=1e-12)),
    ("hemispherical", "nonfinite", lambda mp: hemispherical_albedo(_nan_callable, n=2)),
    # Verdict
    ("verdict", "converged", lambda mp: check(brdfkit.model("lambert", rho_d=0.5))),
    ("verdict", "undetermined", _verdict_undetermined),
    ("verdict", "nonfinite", lambda mp: check(_nan_model())),
    # energy verdicts (issue 22) carry check's status
    ("verdict", "converged", lambda mp: energy_verdict(brdfkit.model("lambert", rho_d=0.5))),
    ("verdict", "undetermined", lambda mp: _verdict_undetermined(mp, energy_verdict)),
    ("verdict", "nonfinite", lambda mp: energy_verdict(_nan_model())),
    # Table 2 rows are verdicts (dicts): the same three keys
    ("verdict", "converged", lambda mp: SimpleNamespace(**table2(models=["lambert"])[0])),
    # Chi2Result
    ("chi2", "converged", lambda mp: chi2_test(brdfkit.model("lambert", rho_d=0.5),
                                               [0.0, 0.0, 1.0], n_samples=20_000, seed=1)),
    ("chi2", "rejected", lambda mp: chi2_test(_overweighted(), [0.0, 0.0, 1.0],
                                              n_samples=20_000, seed=1)),
    ("chi2", "nonfinite", lambda mp: chi2_test(_nan_pdf(), [0.0, 0.0, 1.0],
                                               n_samples=20_000, seed=1, n_theta=4,
                                               n_phi=4)),
    # AmbientTable and SphereRender
    ("render", "converged", lambda mp: __import__("brdfkit.render.ambient", fromlist=["x"])
     .ambient_table(brdfkit.model("lambert", rho_d=0.4), theta_max=1.0)),
    ("render", "limit", _ambient_limit),
    ("render", "converged", lambda mp: _render(model=brdfkit.model("lambert", rho_d=0.5),
                                               phi_l=0.3, size=4, ambient=0.2)),
    ("render", "limit", _render_limit),
    ("render", "nonfinite", lambda mp: _render(model=_nan_model(), phi_l=0.3, size=4)),
    ("render", "converged", lambda mp: _mitsuba(model=brdfkit.model("lambert", rho_d=0.5),
                                                phi_l=0.3, size=4, engine="mitsuba", spp=8)),
    ("render", "undetermined", lambda mp: _mitsuba(model=brdfkit.model("lambert"), phi_l=0.3,
                                                   size=4, engine="mitsuba", spp=1)),
    # FitResult (Lambert fitted by Lambert: exact; modified Phong fitted to a Lambert: the
    # specular lobe's rho_s goes to its lower bound 0)
    ("fit", "converged", lambda mp: _fit(brdfkit.model("lambert"),
                                         brdfkit.model("lambert", rho_d=0.3))),
    ("fit", "at_bound", lambda mp: _fit(brdfkit.model("modified-phong"),
                                        brdfkit.model("lambert", rho_d=0.3))),
]


def _ids():
    seen: dict[str, int] = {}
    out = []
    for kind, name, _ in CASES:
        key = f"{kind}-{name}"
        seen[key] = seen.get(key, 0) + 1
        out.append(key if seen[key] == 1 else f"{key}-{seen[key]}")
    return out


@pytest.mark.parametrize("kind,expected,produce", CASES, ids=_ids())
def test_every_result_states_its_status(kind, expected, produce, monkeypatch):
    table = STATUS[kind]
    result = produce(monkeypatch)
    codes = np.unique(np.asarray(result.status)).tolist()  # AlbedoResult: one per angle
    for code in codes:
        assert code in table, (kind, code)
    assert table[expected].code in codes, (kind, expected, codes, result.message)
    worst = max(codes, key=lambda c: (not table.success(c), c))
    assert result.success is all(table.success(c) for c in codes)
    assert isinstance(result.success, bool)
    assert table.message(worst) in result.message, (result.message, table.message(worst))
