"""
Reports written from computed results (layer 4)
===============================================

- :mod:`brdfkit.report.fit_study` — ``docs/fitting-study.md`` and its figures from the
  files of :func:`brdfkit.fitting.study.run_study`: the writer, one function per section,
  over :mod:`brdfkit.report.fit_study_verdicts` (every claim's test and verdict) and
  :mod:`brdfkit.report.fit_study_figures` (the report's figures); the study's CSV cells
  are read by ``brdfkit.report._study_rows``.
- :mod:`brdfkit.report.energy_table` — the energy table of issue 22 (rows as model specs,
  the papers' claims; ``brdfkit verdicts``), :mod:`brdfkit.report.energy_findings` (the
  findings tested on its rows) and ``disney_diffuse.py`` (Burley's diffuse term alone, a
  model file the table loads by path).
"""
