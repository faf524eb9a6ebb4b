"""Burley's (2012) diffuse term alone, as a user model file (``brdfkit.formula``).

The energy table (:mod:`brdfkit.report.energy_table`) measures "Disney's diffuse" by
itself: the registered ``disney`` cannot switch its specular lobe off (with ``specular``
and ``metallic`` 0 its Fresnel is still Schlick's (1 − cos θ_d)⁵ at grazing), so its
diffuse term is written here from the course notes, §5.3:

    f_d = (base_color/π) (1 + (F_D90 − 1)(1 − cos θ_l)⁵) (1 + (F_D90 − 1)(1 − cos θ_v)⁵),
    F_D90 = ½ + 2 roughness cos²θ_d,

with cos θ_d = ω_i·h = |ω_i + ω_o|/2. ``base_color`` is linear here (the registered
model's C^2.2 of 1 is 1: the white setting is the same). Loaded as a spec by its path
(``brdfkit.model(PATH)``); importing it as a module only declares it. It equals the
registered ``disney`` (specular = metallic = sheen = clearcoat = subsurface = 0) wherever
ω_i = ω_o, where Schlick's factor of the specular is 0 (``tests/test_energy_verdicts.py``).

Reference: B. Burley, "Physically-Based Shading at Disney", SIGGRAPH 2012 course notes,
§5.3 (diffuse).
"""

from brdfkit.formula import Param, define, formula, maximum

INV_PI = 0.3183098861837907  # 1/π


@formula
def _schlick(c):
    m = maximum(1.0 - c, 0.0)  # rounding can put cos θ_d a hair above 1
    m2 = m * m
    return m2 * m2 * m


@formula
def burley_diffuse(ix, iy, iz, ox, oy, oz, base_color, roughness):
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    cos_d2 = 0.25 * (sx * sx + sy * sy + sz * sz)  # cos²θ_d = |ω_i + ω_o|²/4
    fd90m1 = 2.0 * roughness * cos_d2 - 0.5  # F_D90 − 1
    return base_color * INV_PI * (1.0 + fd90m1 * _schlick(iz)) * (1.0 + fd90m1 * _schlick(oz))


MODEL = define(
    "disney_diffuse", eval=burley_diffuse, reciprocal=True, isotropic=True,
    params=[Param("base_color", 1.0, 0.0, 1.0, doc="linear base colour", kind="colour"),
            Param("roughness", 1.0, 0.0, 1.0, doc="Burley's roughness")],
    citation="Burley 2012, course notes §5.3 (the diffuse term)",
    summary="Burley's 2012 diffuse term alone (retro-reflection, no subsurface)")
