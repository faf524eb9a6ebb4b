"""
Figures of the papers, reproduced by computation
================================================

A registry of named figures. Each figure function takes no required
arguments and returns a Matplotlib :class:`~matplotlib.figure.Figure`
(Agg backend) with labelled axes, a legend and a caption naming the paper
figure; :func:`save_figure` writes PNG or SVG atomically.

Layout (imports go downward only)
---------------------------------
- :mod:`~brdfkit.figures._save` — output-path checks and the atomic writer;
  knows no figure.
- :mod:`~brdfkit.figures.lewis` (``lewis-fig5``, ``lewis-fig7``,
  ``lewis-fig8``, ``lewis-fig9``), :mod:`~brdfkit.figures.lewis_spheres`
  (``lewis-fig3``, ``lewis-fig4``, ``lewis-fig6``, ``lewis-fig10``: rendered
  spheres), :mod:`~brdfkit.figures.neumann`
  (``neumann-fig1``), :mod:`~brdfkit.figures.pumping` (``neumann-fig3`` …
  ``neumann-fig7``), :mod:`~brdfkit.figures.neumann_fig8` (``neumann-fig8``: a
  Monte-Carlo render through Mitsuba, options ``spp``, ``size``, ``seed``) — plain
  figure functions; they import the library, never
  :mod:`brdfkit.figures`.
- :mod:`~brdfkit.figures.fitting` — :func:`~brdfkit.figures.fitting.fit_figure`, the
  figure of one fit (``brdfkit fit --plot``; it takes a result, so it is not registered).
- :mod:`~brdfkit.figures._registry` — :data:`FIGURES`, the explicit list of
  name → function, :data:`MODEL_FIGURES` (figures of given models, e.g.
  ``slices`` in :mod:`~brdfkit.figures.models`), and the functions that use them.

Public objects
--------------
- :data:`FIGURES` — name → figure function (read-only mapping).
- :data:`FIGURE_OPTIONS` — name → the keyword options a figure takes.
- :func:`make_figure`, :func:`save_figure`, :func:`figure_names`,
  :func:`resolve_figure`.
- :func:`save_atomic`, :func:`check_output_path` — for plots that are not
  registered figures (e.g. ``brdfkit albedo --plot``).
"""

from __future__ import annotations

from brdfkit.figures._registry import (
    FIGURE_OPTIONS,
    FIGURES,
    MODEL_FIGURES,
    figure_names,
    make_figure,
    resolve_figure,
    save_figure,
)
from brdfkit.figures._save import check_output_path, save_atomic

__all__ = ["FIGURES", "FIGURE_OPTIONS", "MODEL_FIGURES", "make_figure", "save_figure",
           "figure_names", "resolve_figure", "save_atomic", "check_output_path"]
