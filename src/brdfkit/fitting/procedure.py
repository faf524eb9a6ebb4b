"""
Fitting a model to a measured material
======================================

:func:`fit` adjusts a model's parameters (read from its ``params``
declaration: defaults, bounds, kinds — no second list) so that it matches a
target (any brdfkit model: a built-in material, a MERL ``.binary``
:class:`~brdfkit.data.MeasuredBRDF`, another model) on the MERL grid
(:mod:`brdfkit.fitting.samples`) under one of the losses of
:mod:`brdfkit.fitting.losses`, and returns a :class:`FitResult` with every
metric, the albedos and a convergence record.

Procedure
---------
Free parameters: every declared parameter except choices (kept as given),
optional ones that are None (e.g. no η: F = 1 stays so) and those in
``fixed``; colour parameters per channel of the target, scalars shared, lobe
parameters per lobe. A parameter that changes nothing on the samples (e.g. an
extinction coefficient without an η) is held and reported as ``inert``.
Linear parameters (colour parameters the model is affine in, found
numerically for each candidate and then jointly — so a non-linear colour
parameter such as η does not stop ρ_d, k_s from being linear; see
:mod:`brdfkit.fitting._problem`) are solved in closed form; the others
("shape") are optimised over bounded reparametrisations
(:mod:`brdfkit.fitting._space`) with Nelder–Mead.

Stages of ``procedure="staged"`` (= ``"auto"``, any model):

(i) first guess and linear parameters: the width parameter (the model's
    ``width_param``) from the measured peak's half-width β (via
    ``width_from_beta``) and from the ladder β = 0.5°, 1°, …, 64°
    (:data:`~brdfkit.fitting._guess.BETA_LADDER_DEG`), each with the linear
    parameters solved; the width of least loss is kept (a measured peak alone can mislead: the clear
    coat of two-layer-silver gives β → 0, s ≈ 10⁶, a local optimum on the
    spike far from the broad lobe); the linear parameters solved there.
(ii) search over the shape parameters on a coarser grid
    (:data:`SEARCH_STRIDES`: ~2,700 samples, every θ_h and θ_d cell kept) with the
    linear ones re-solved at every evaluation (variable projection), from
    several starts: the guess; with free optional parameters (η), the same
    model without them fitted first (recursively) and its optimum with those
    parameters where they change the model least (the z of
    :data:`NEUTRAL_Z` of least loss; for η: η → 0, F = 1 under total internal
    reflection) — so a free optional parameter never makes the fit worse;
    for a parameter whose bounds are sub-models (``BRDF.fit_bound_starts``:
    Nielsen's α, 0 Phong-like, 1 Blinn-like) two starts near its bounds
    (:data:`BOUND_START_Z`), which always run — under ``procedure="nielsen"``
    the two sub-models at the bounds fitted first instead, their optima taken
    as they are, so that the α-mix is never worse than either end; the declared defaults (an
    optional parameter declared None keeps its value); ``n_starts − 2``
    random ones (z of the guess plus N(0, 1), from
    ``numpy.random.default_rng(seed)``) — ``n_starts`` starts in all besides the
    nested one, the bound starts first after the guess. A shape parameter whose
    start sits at a bound of its range (a conductor's κ at its default 0: its
    coordinate saturated, the simplex cannot move it) is first moved off it
    (``_starts.off_the_bounds``: the guess at the best z of a scan, the bounds
    included; the defaults at the best interior local minimum). Every run is
    recorded; once two runs reach the same loss (relative difference ≤
    :data:`CONSENSUS`) the remaining starts (but bound starts) are recorded
    as skipped. ``procedure="nielsen"`` compares the runs with their linear
    parameters re-solved.
(iii) polish on the fit's own samples from the best run: for l1, l2 and ngan
    (``Loss.exact_projection``) the shape with the linear parameters re-solved —
    variable projection is exact for them (min over (shape, linear) = min over
    shape of the loss with the linear part solved), so this is the joint optimum,
    the final L1 solve run to convergence (:data:`IRLS_FINAL` steps); for log and
    perceptual (linear part solved under L2) all free parameters jointly under the loss.

``procedure="nielsen"`` (Nielsen et al. 2015, "Fitting Results and
Observations"): (i) as above (ρ_d and k_s); (ii) the shape parameters (s, α
and η) with the linear ones solved at each start and then held; (iii) the
shape parameters with the linear parameters whose basis depends on the shape
(k_s, not ρ_d: as the paper's stage (iii) frees s, α, k_s), jointly under
the loss. ``"direct"``: all free parameters jointly from the first guess (one
stage, no linear solve: the plain approach, for comparison).

A derived model with a ``BRDF.fit_base`` and no linear parameters — a pumped model (g
depends on them) — is started from the fit of its base, the unpumped root (the root's own
staged fit as stage (ii)), then stage (iii) optimises all its parameters jointly. A
one-times pumped model is evaluated during the fit through
:func:`brdfkit.pumping.surrogate.surrogate` (albedo tables per shape parameter value,
interpolated, linear parameters combined without a new table); the result, its metrics and
albedos are the exact model's, and ``convergence["surrogate"]`` records the surrogate's loss
at the result next to them, and, evaluations being cheap, all parameters get one run with
stage (ii)'s full steps before stage (iii)'s polish. Where the pumped model does not see a
common scale of its linear parameters (g₁: f/g is homogeneous of degree 0 in them), one per
channel is held at the root's value (``convergence["scale_held"]``;
:mod:`brdfkit.fitting._pumped`).

Stopping and status: a Nelder–Mead run stops when its vertices' losses agree
to :data:`FRTOL` of the loss after stage (i), or after
:data:`~brdfkit.fitting._simplex.STALL_EVALS` evaluations per coordinate without
such an improvement (a flat valley, or a bound approached asymptotically in z);
its stop is checked by one restart from the best point. The status is set by
the last stage: ``limit`` (``brdfkit.status.STATUS["fit"]``) when it reached its budget
(a stage-(ii) search cut by its budget and then polished to the tolerance is recorded but
converged).
A polish cut by its budget is run once more (stage "iii'") with the
coordinates at (or indistinguishable from) a bound set there and held: it
converges where the crawl was towards a bound approached only asymptotically
in z; with none at a bound, once more with the search's (ten times larger)
steps, which travels along a long valley where the polish's small simplex
crawled. Bounds are checked after the last stage: a coordinate at a bound, or
one the loss cannot tell from a bound (moved there the loss rises by less than
:data:`BOUND_LOSS_RTOL` relative; the bound is taken if the loss falls), is
reported (``at_bounds``, status ``at_bound``, named in the message with its value
and which bound) — never a plain "converged". One the loss cannot tell from *either*
bound of a finite range is not at a bound but **inert** (the data do not determine
it: the exponent of a lobe whose weight is 0): it stays where the fit left it, is
listed in ``convergence.inert`` and named in the message as inert. Every stage
record lists the coordinates at a bound after it.

Procedures as data
-------------------
A procedure is a :class:`Procedure`: the stages it runs, in order — methods of
:class:`brdfkit.fitting._run.FitRun`, one per stage — and the options its stages read;
:data:`PROCEDURES` lists them (``"auto"`` is ``"staged"``, for any model: :data:`ALIASES`)
and :func:`get_procedure` dispatches, its error listing the names. The stages and the parameter
space (:class:`brdfkit.fitting._space.ParameterSpace`) are described in those modules; the
convergence record is :class:`brdfkit.fitting._records.Convergence`.

Public objects
--------------
- :func:`fit`, :class:`FitResult`, :class:`Procedure`, :data:`PROCEDURES`,
  :func:`get_procedure`, :data:`PROCEDURE_NAMES`, :data:`STATUS_MESSAGES`
  (``STATUS["fit"].messages``).

The fit evaluates on one thread (:class:`brdfkit._threads.numba_threads`, restored
after): for ~15,000 pairs the parallel driver's thread wake-ups cost more
than the work on a shared 2-core machine (measured: 16 ms vs 0.3 ms).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from brdfkit._threads import numba_threads
from brdfkit.errors import ParameterError
from brdfkit.fitting._checks import check_channels, check_fit_args, check_samples
from brdfkit.fitting._result import FitResult
from brdfkit.fitting._run import (  # noqa: F401 - the procedure's constants, documented here
    BOUND_LOSS_RTOL,
    CONSENSUS,
    FRTOL,
    FRTOL_POLISH,
    IRLS_FINAL,
    POLISH_MIN_EVALS,
    SEARCH_STRIDES,
    STAGES,
    FitRun,
    Settings,
)
from brdfkit.fitting._starts import BOUND_START_Z, NEUTRAL_Z  # noqa: F401 - as above
from brdfkit.fitting.losses import REGISTRY as LOSS_REGISTRY
from brdfkit.fitting.losses import loss as get_loss
from brdfkit.fitting.samples import DEFAULT_STRIDES
from brdfkit.models import BRDF
from brdfkit.status import STATUS

__all__ = ["fit", "FitResult", "Procedure", "PROCEDURES", "get_procedure", "PROCEDURE_NAMES",
           "ALIASES", "STATUS_MESSAGES"]

#: Status codes of a fit (FitResult.status), by name: brdfkit.status.STATUS["fit"].
CONVERGED, AT_BOUND, MAX_EVALS, NONFINITE = (STATUS["fit"].CONVERGED, STATUS["fit"].AT_BOUND,
                                             STATUS["fit"].LIMIT, STATUS["fit"].NONFINITE)
#: code → message of a fit's status (the one vocabulary: brdfkit.status).
STATUS_MESSAGES = STATUS["fit"].messages
#: Losses whose linear solve is exact (Loss.exact_projection).
EXACT_PROJECTION = tuple(n for n, L in LOSS_REGISTRY.items() if L.exact_projection)


@dataclass(frozen=True)
class Procedure:
    """A fitting procedure: its stages (methods of :class:`~brdfkit.fitting._run.FitRun`,
    run in order) and the options they read.

    Attributes
    ----------
    name, summary : str
    stages : tuple of str
        Names from :data:`~brdfkit.fitting._run.STAGES`, in their order.
    hold_linear_in_search : bool
        Stage (ii) solves the linear parameters at each start and holds them (Nielsen's
        (ii)), instead of re-solving them at every evaluation.
    prefit_bound_ends : bool
        The sub-models at the bounds of ``BRDF.fit_bound_starts`` parameters are fitted
        first and compared as they are, instead of starts near the bounds.
    polish_frees : {"all", "shape-dependent"}
        Stage (iii), where the projection is not exact, frees every parameter or the
        shape and the linear parameters whose basis depends on it (Nielsen's (iii)).
    polish_label : str
        Stage (iii)'s name in the record (where it is not the projected polish).
    """

    name: str
    summary: str
    stages: tuple
    hold_linear_in_search: bool = False
    prefit_bound_ends: bool = False
    polish_frees: str = "all"
    polish_label: str = "all"

    def __post_init__(self):
        bad = [s for s in self.stages if s not in STAGES]
        order = [STAGES.index(s) for s in self.stages if s in STAGES]
        if bad or order != sorted(order):
            raise ValueError(f"procedure {self.name!r}: stages must be among {STAGES}, in "
                             f"that order; got {self.stages}")


_ALL = STAGES
#: Every procedure, by name (module docstring); "auto" resolves to "staged".
PROCEDURES: dict[str, Procedure] = {p.name: p for p in (
    Procedure("staged", "first guess, linear parameters in closed form, multi-start "
                        "shape search, polish (any model)", _ALL),
    Procedure("nielsen", "Nielsen et al. 2015's three stages: linear parameters held in "
                         "the shape search, ends of a mix fitted first, shape and "
                         "shape-dependent linear parameters polished", _ALL,
              hold_linear_in_search=True, prefit_bound_ends=True,
              polish_frees="shape-dependent",
              polish_label="shape and shape-dependent linear"),
    Procedure("direct", "all free parameters jointly from the first guess (one stage, no "
                        "linear solve: the plain approach, for comparison)",
              ("first_guess", "hold_inert", "loss_scale", "polish", "bound_polish")),
)}
#: Other names of procedures: "auto", the choice for any model.
ALIASES = {"auto": "staged"}
#: Names a fit accepts (the CLI's --procedure choices): "auto" and the procedures.
PROCEDURE_NAMES = (*ALIASES, *PROCEDURES)


def get_procedure(name) -> Procedure:
    """The procedure *name* (an alias of :data:`ALIASES` resolved); the error lists the
    names."""
    if isinstance(name, Procedure):
        return name
    try:
        return PROCEDURES[ALIASES.get(name, name)]
    except (KeyError, TypeError):
        raise ParameterError(f"fit: procedure must be one of {', '.join(PROCEDURE_NAMES)}; "
                             f"got {name!r}") from None


# --------------------------------------------------------------------------- fit
def fit(model: BRDF, target: BRDF, *, loss: str = "l1", procedure: str = "auto",
        fixed: dict | None = None, theta_max: float | None = None, seed: int = 0,
        n_starts: int = 3, strides=DEFAULT_STRIDES, max_evals: int = 200,
        progress=None) -> FitResult:
    """Fit *model*'s parameters to *target* (see the module docstring).

    Parameters
    ----------
    model : BRDF
        The model to fit (a registered model, a pumped one); its current values are
        the defaults of the parameters not otherwise set.
    target : BRDF
        What to fit: ``brdfkit.data.material(spec)``, a MeasuredBRDF, any model.
    loss : {"l1", "l2", "ngan", "log", "perceptual"}
        The loss minimised (:mod:`brdfkit.fitting.losses`; weights stated there).
    procedure : {"auto", "staged", "nielsen", "direct"}
    fixed : dict, optional
        Parameters held at the given values (validated by the model).
    theta_max : float, optional
        Keep only pairs with θ_i, θ_o ≤ theta_max (radians); e.g. ``math.radians(80)``.
    seed : int
        Seed of the random starts (the result is reproducible with it).
    n_starts : int
        Runs of stage (ii): guess, defaults, then n_starts − 2 random ones (≥ 1).
    strides : (int, int)
        Subsampling of the MERL grid (:func:`~brdfkit.fitting.samples.merl_samples`).
    max_evals : int
        Nelder–Mead evaluations per run of a stage (per free coordinate: × its count,
        at least this).
    progress : callable, optional
        ``progress(stage, evaluations, loss)`` after each finished stage (the explorer's
        and the CLI's progress display); it does not change the fit.

    Raises
    ------
    ParameterError
        Unknown loss or procedure, bad fixed values, n_starts < 1, non-model inputs; seed
        not an integer >= 0, max_evals not an integer >= 1, progress not callable, fixed
        not a dict, strides not two integers >= 1, theta_max outside (0, pi/2] or leaving
        no sample pair, a coloured model whose channel count is neither 1 nor the
        target's.
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"fit: model must be a brdfkit model; got {type(model).__name__}")
    if not isinstance(target, BRDF):
        raise ParameterError(f"fit: target must be a brdfkit model or material (e.g. "
                             f"brdfkit.data.material('merl:nickel')); got "
                             f"{type(target).__name__}")
    objective = get_loss(loss)  # the errors list the names
    proc = get_procedure(procedure)
    if not (isinstance(n_starts, int | np.integer) and not isinstance(n_starts, bool)
            and n_starts >= 1):
        raise ParameterError(f"fit: n_starts must be an integer >= 1; got {n_starts!r}")
    fixed, theta_max, strides = check_fit_args(fixed=fixed, theta_max=theta_max, seed=seed,
                                               strides=strides, max_evals=max_evals,
                                               progress=progress)
    if fixed:
        model = model.with_params(**fixed)  # validates names and values
        fixed = {k: model.values[k] for k in fixed}
    check_channels(model, target)
    check_samples(strides=strides, theta_max=theta_max)
    with numba_threads(1):  # see the module docstring
        settings = Settings(loss=objective, procedure=proc, theta_max=theta_max, seed=seed,
                            n_starts=n_starts, strides=strides, max_evals=max_evals)
        return FitRun(model, target, settings, fixed, progress).run()
