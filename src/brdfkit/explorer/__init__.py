"""
brdfkit explore: a browser app to look at models, pumped models and materials
=============================================================================

- :mod:`brdfkit.explorer.views` — the views as functions (model, direction →
  arrays, PNG); no browser, tested on their own.
- :mod:`brdfkit.explorer.app` — the thin web layer (FastAPI): the page and a JSON
  API over the views.
- :mod:`brdfkit.explorer.files` — models from files: watched (stamp, content hash),
  reloaded on save with the last good version kept, opened by path.
- :mod:`brdfkit.explorer.serve` — ``brdfkit explore``: serve on 127.0.0.1, open the
  browser, stop cleanly on Ctrl-C.
"""
