"""
Reports written from computed results (layer 4)
===============================================

- :mod:`brdfkit.report.fit_study` — ``docs/fitting-study.md`` and its figures from the
  files of :func:`brdfkit.fitting.study.run_study`.
"""
