"""
Data commands: ``materials`` and ``export``
===========================================

- ``brdfkit materials [SPEC ...] [--representations] [--json]`` — the built-in
  measured materials with source, licence and albedo estimate.
- ``brdfkit export SPEC [-p ...] [--pump ...] --out FILE.binary`` — any model,
  pumped model or material on the MERL grid, written atomically.

Plain click commands; :mod:`brdfkit.cli` adds them to the ``brdfkit`` group.
"""

from __future__ import annotations

import time

import click

import brdfkit.cli._progress as _progress
from brdfkit._io import check_output_path
from brdfkit.cli._common import build_model, emit_json, model_options
from brdfkit.data import material, materials
from brdfkit.data.catalog import material_info, normal_albedo
from brdfkit.data.export import export_merl

__all__ = ["materials_cmd", "export_cmd"]


@click.command("materials")
@click.argument("specs", nargs=-1, metavar="[SPEC]...")
@click.option("--representations", is_flag=True,
              help="Also list the NPF, ABC and SGD fits of the MERL materials (459 rows).")
@click.option("--json", "as_json", is_flag=True,
              help="Print a JSON list of {name, source, material, representation, licence, "
                   "citation, albedo, rho_d}.")
def materials_cmd(specs, representations, as_json):
    """List the built-in measured materials (or only SPEC ...).

    159 materials: 100 MERL (NBRDF surrogate by default; @npf, @abc, @sgd
    with --representations), 51 RGL-EPFL and 8 Nielsen et al. 2015. Each row
    gives the spec to pass wherever a model name goes, the data source, the
    licences and the albedo estimate a(0) per RGB channel (directional albedo
    at normal incidence; for glossy materials it includes the specular
    lobe). MERL data: Matusik et al. 2003, CC-BY-SA-4.0 — keep the
    attribution in derived work.
    """
    with _progress.working("materials: their albedo a(0)", as_json=as_json):
        rows = ([material_info(s) for s in specs] if specs
                else materials(representations=representations))
    if as_json:
        emit_json([r.to_dict() for r in rows])
        return
    width = max(len(r.name) for r in rows)
    click.echo(f"{'spec'.ljust(width)}  {'a(0) R     G     B':19s}  licence")
    for r in rows:
        a = " ".join(f"{x:5.3f}" for x in r.albedo)
        click.echo(f"{r.name.ljust(width)}  {a:19s}  {r.licence}")
    if not specs:
        click.echo(f"\n{len(rows)} materials; pass a spec wherever a model name goes "
                   "(e.g. brdfkit eval merl:nickel --wi 30,0 --wo 30,180).")


@click.command("export")
@model_options
@click.option("--out", "out", required=True, metavar="FILE.binary",
              help="Output MERL .binary file (written atomically; the directory must exist).")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"model", "params", "out", "seconds", "normal_albedo"}.')
def export_cmd(model, param, compensate, pump, times, out, as_json):
    """Write MODEL (a model, pumped model or material) onto the MERL grid as FILE.binary.

    Each bin holds f_r at the centre of its index coordinates (theta_h =
    ((i+1/2)/90)^2 * 90 deg, theta_d = (j+1/2) deg, phi_d = (k+1/2) deg,
    phi_h = 0); bins with a direction at or below the horizon are written -1
    (MERL's "not measured"). One-channel models are written grey. BRDF
    Explorer, ALTA, bbm and Mitsuba pipelines read the file; 'brdfkit eval
    FILE.binary ...' reads it back.
    """
    check_output_path(out, option="--out", suffixes=(".binary",))
    with _progress.working(f"exporting {model}", as_json=as_json):
        m = build_model(model, param, pump=pump, times=times, compensate=compensate)
        t0 = time.perf_counter()
        path = export_merl(m, out)
        seconds = time.perf_counter() - t0
        written = normal_albedo(material(path))
    lost = _lost_lobe(m, written)
    if lost:
        click.echo(f"brdfkit: warning: {path}: {lost}", err=True)
    if as_json:
        d = m.to_dict()
        emit_json({"model": d["model"], "params": d["params"],
                   **{k: d[k] for k in ("compensate", "pump") if k in d}, "out": path,
                   "seconds": seconds, "normal_albedo": written})
        return
    click.echo(path)


#: ``export`` warns when the normal-incidence albedo of the written table differs from the
#: model's (albedo engine) by more than this fraction. Measured for GGX ``microfacet``: the
#: MERL grid keeps it within 0.7 % at alpha = 0.01, 9.5 % at alpha = 1e-3, and loses the
#: whole lobe at 1e-8 (0 where the model has 1); modified-phong n = 1e5 differs by 3.4 %.
EXPORT_ALBEDO_TOL = 0.05


def _lost_lobe(m, written) -> str | None:
    """Why the written table is not *m* (its normal albedo is off by more than
    :data:`EXPORT_ALBEDO_TOL`), or None."""
    import numpy as np

    from brdfkit.analysis import albedo
    from brdfkit.geometry import merl_theta_h

    res = albedo(m, 0.0)
    a_model = np.atleast_1d(np.asarray(res.albedo, dtype=np.float64))
    a_file = np.atleast_1d(np.asarray(written, dtype=np.float64))
    a_model = np.broadcast_to(a_model, np.broadcast_shapes(a_model.shape, a_file.shape))
    scale = np.maximum(np.abs(a_model), np.abs(a_file))
    off = np.abs(a_file - a_model) > EXPORT_ALBEDO_TOL * scale
    if not (res.success and np.any(off & (scale > 0.0))):
        return None
    c = int(np.argmax(np.where(off, np.abs(a_file - a_model) / np.where(scale > 0, scale, 1), 0)))
    width = min((lobe.width for lobe in m.lobes()), default=None)
    first_bin = float(merl_theta_h(1.0 / 90.0))
    lobe = (f"; its narrowest lobe is {width:.3g} rad wide, the grid's first theta_h bin "
            f"{first_bin:.3g} rad" if width is not None else "")
    return (f"the MERL grid does not represent {m.name}: normal-incidence albedo "
            f"{a_file[c]:.4g} in the file vs {a_model[c]:.4g} of the model (channel {c}, "
            f"off by more than {EXPORT_ALBEDO_TOL:.0%}){lobe}; the file is written but "
            "is not this model (use a wider lobe)")
