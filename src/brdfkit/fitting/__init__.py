"""
Fitting models to measured materials
====================================

- :mod:`brdfkit.fitting.batch` — batches of fits: resumable, written row by row,
  local processes or a Dask cluster.
"""
