"""The figure registry: every figure name listed once, explicitly.

Each figure module (:mod:`~brdfkit.figures.lewis`,
:mod:`~brdfkit.figures.lewis_spheres`,
:mod:`~brdfkit.figures.neumann`, :mod:`~brdfkit.figures.pumping`) defines
plain functions and imports nothing from :mod:`brdfkit.figures`; this module
imports them (downward) and names them. To add a figure, write the function
in its paper's module and add one line to :data:`FIGURES`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType

from brdfkit.errors import BrdfkitError
from brdfkit.figures import energy, lewis, lewis_spheres, neumann
from brdfkit.figures import models as model_figures
from brdfkit.figures import neumann_fig8 as neumann_fig8_module
from brdfkit.figures import nielsen as nielsen_figures
from brdfkit.figures import pumping as pumping_figures
from brdfkit.figures._save import check_output_path, save_atomic

__all__ = ["FIGURES", "FIGURE_OPTIONS", "MODEL_FIGURES", "figure_names", "resolve_figure",
           "make_figure", "save_figure"]

#: name → function returning a Matplotlib Figure (read-only: edit the list here).
FIGURES: Mapping[str, Callable] = MappingProxyType({
    "lewis-fig3": lewis_spheres.lewis_fig3,
    "lewis-fig4": lewis_spheres.lewis_fig4,
    "lewis-fig5": lewis.lewis_fig5,
    "lewis-fig6": lewis_spheres.lewis_fig6,
    "lewis-fig7": lewis.lewis_fig7,
    "lewis-fig8": lewis.lewis_fig8,
    "lewis-fig9": lewis.lewis_fig9,
    "lewis-fig10": lewis_spheres.lewis_fig10,
    "neumann-fig1": neumann.neumann_fig1,
    "nielsen-fig1": nielsen_figures.nielsen_fig1,
    "neumann-fig3": pumping_figures.neumann_fig3,
    "neumann-fig4": pumping_figures.neumann_fig4,
    "neumann-fig5": pumping_figures.neumann_fig5,
    "neumann-fig6": pumping_figures.neumann_fig6,
    "neumann-fig7": pumping_figures.neumann_fig7,
    "neumann-fig8": neumann_fig8_module.neumann_fig8,
    "energy-reciprocity": energy.energy_reciprocity,
})

#: name → the keyword options a figure takes (rendered panels: the CLI's --spp, --panel-size
#: (size), --seed); figures not listed take none.
FIGURE_OPTIONS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "neumann-fig8": ("spp", "size", "seed"),
    "nielsen-fig1": ("size",),
})

#: name → function of the models to draw (``f(*models)`` → Figure): figures of any model or
#: material, given by the caller (the CLI's ``--model``/``--compare``).
MODEL_FIGURES: Mapping[str, Callable] = MappingProxyType({
    "slices": model_figures.model_slices,
})


def figure_names() -> list[str]:
    """Registered figure names (paper figures and model figures), sorted."""
    return sorted([*FIGURES, *MODEL_FIGURES])


def resolve_figure(name: str) -> str:
    """The registered name for *name* (case and surrounding blanks ignored), or BrdfkitError."""
    key = str(name).strip().lower()
    if key not in FIGURES and key not in MODEL_FIGURES:
        raise BrdfkitError(f"unknown figure {name!r}; valid names: " + ", ".join(figure_names()))
    return key


def _check_options(key: str, options: dict) -> None:
    allowed = FIGURE_OPTIONS.get(key, ())
    extra = sorted(set(options) - set(allowed))
    if extra:
        takes = (f"it takes {', '.join(allowed)}" if allowed else "it takes none")
        raise BrdfkitError(f"figure {key} has no option {', '.join(extra)} ({takes}; figures "
                           f"with options: {', '.join(FIGURE_OPTIONS)})")


def make_figure(name: str, models=(), **options):
    """Build the figure *name* (a Matplotlib Figure); *models* for :data:`MODEL_FIGURES`,
    *options* (keyword) for the figures of :data:`FIGURE_OPTIONS`."""
    key = resolve_figure(name)
    _check_options(key, options)
    if key in MODEL_FIGURES:
        if not models:
            raise BrdfkitError(f"figure {key} draws given models: pass at least one model "
                               f"(the CLI: brdfkit figure {key} MODEL)")
        return MODEL_FIGURES[key](*models)
    if models:
        raise BrdfkitError(f"figure {key} reproduces a paper figure with its own models; it "
                           f"takes no model (figures that do: {', '.join(MODEL_FIGURES)})")
    return FIGURES[key](**options)


def save_figure(name: str, path, *, dpi: int = 150, option: str = "path", models=(),
                options: dict | None = None) -> str:
    """Build figure *name* and write it to *path* (.png or .svg); return *path*.

    The name and the path are checked before the (possibly long) computation.
    *option* is how the caller names *path* in error messages (the CLI passes
    ``"--out"``). *models* are the models a :data:`MODEL_FIGURES` figure draws;
    *options* the keyword options of a :data:`FIGURE_OPTIONS` figure.
    """
    import matplotlib.pyplot as plt

    key = resolve_figure(name)
    _check_options(key, options or {})
    check_output_path(path, option=option)
    fig = make_figure(name, models, **(options or {}))
    try:
        return save_atomic(fig, path, dpi=dpi, option=option)
    finally:
        plt.close(fig)
