"""
Reports written from computed results (layer 4)
===============================================

- :mod:`brdfkit.report.fit_study` — ``docs/fitting-study.md`` and its figures from the
  files of :func:`brdfkit.fitting.study.run_study`: the writer, one function per section,
  over :mod:`brdfkit.report.fit_study_verdicts` (every claim's test and verdict) and
  :mod:`brdfkit.report.fit_study_figures` (the report's figures); the study's CSV cells
  are read by ``brdfkit.report._study_rows``.
"""
