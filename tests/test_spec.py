"""brdfkit.spec.ModelSpec: one description of a model, from words or a dict, and back.

References of the values checked here:
- every registered model: the spec built from the command line's words of each of its
  ``examples`` has the values of the class built directly from the example's keyword
  arguments (a second path), and ``from_dict(m.to_dict())`` rebuilds ``m`` (same values,
  bit-equal ``eval``);
- ``beta``: closed forms of the half-angle, cosⁿβ = 1/2 → n = −ln 2 / ln cos β (Lewis
  §3.1) and, for GGX, D(β) = D(0)/2 with D ∝ 1/(cos⁴θ (α² + tan²θ)²) → α² = sin²β /
  (√2 − cos²β) (solved by hand from the GGX D of Walter et al. 2007 eq. 33);
- pumped models: :func:`brdfkit.pumping.pump` applied by hand to the same base.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import brdfkit
from brdfkit.errors import BrdfkitError, ParameterError, UnknownModelError
from brdfkit.pumping import from_dict as pumping_from_dict
from brdfkit.pumping import pump
from brdfkit.spec import KINDS, OPERATORS, ModelSpec, Operator


def _pairs(n=40, seed=3):
    rng = np.random.default_rng(seed)

    def hemi():
        z = rng.uniform(0.05, 1.0, n)
        ph = rng.uniform(0.0, 2.0 * math.pi, n)
        s = np.sqrt(1.0 - z * z)
        return np.stack([s * np.cos(ph), s * np.sin(ph), z], axis=-1)

    return hemi(), hemi()


def _word(v) -> str | None:
    """A parameter value as typed after -p NAME= (None: not expressible as one word)."""
    if v is None:
        return "none"
    if isinstance(v, str):
        return v
    if isinstance(v, list | tuple):
        if any(isinstance(x, list | tuple) for x in v):
            return None
        return ",".join(repr(float(x)) for x in v)
    return repr(float(v))


def _same_values(a: dict, b: dict) -> None:
    assert set(a) == set(b)
    for k in a:
        if isinstance(a[k], str) or a[k] is None:
            assert a[k] == b[k], k
        else:
            np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


# --------------------------------------------------------------------------- every model
@pytest.mark.parametrize("name", list(brdfkit.MODELS))
def test_words_dict_build_round_trip_every_model(name):
    cls = brdfkit.MODELS[name]
    wi, wo = _pairs()
    for example in cls.examples or ({},):
        words = {k: _word(v) for k, v in example.items()}
        if any(w is None for w in words.values()):
            continue  # a nested per-lobe-per-channel value has no command-line word
        spec = ModelSpec.parse(name, [f"{k}={w}" for k, w in words.items()])
        assert spec.kind == "model" and spec.name == name
        m = spec.build()
        direct = cls(**example)
        _same_values(m.values, direct.values)
        # the dict form is the model's own, and it rebuilds the model
        d = m.to_dict()
        again = ModelSpec.from_dict(d)
        assert again == ModelSpec.of(m) and again.to_dict() == d
        assert json.loads(json.dumps(again.to_dict())) == d
        rebuilt = again.build()
        _same_values(rebuilt.values, m.values)
        np.testing.assert_array_equal(rebuilt.eval(wi, wo), m.eval(wi, wo))
        # and the spec of the words round-trips through its own dict
        assert ModelSpec.from_dict(spec.to_dict()) == spec


def test_spec_is_an_immutable_value():
    a = ModelSpec.parse("modified-phong", ["n=20", "rho_d=0.1"])
    b = ModelSpec.parse("modified-phong", ["rho_d=0.1", "n=20"])
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a != ModelSpec.parse("modified-phong", ["n=21", "rho_d=0.1"])
    with pytest.raises(AttributeError, match="immutable"):
        a.target = "lambert"
    p = a.params
    p["n"] = 1.0  # a copy: the spec does not change
    assert a.params == {"n": 20.0, "rho_d": 0.1}
    c = ModelSpec.parse("modified-phong", ["rho_s=0.1,0.2,0.3"])
    assert c.params == {"rho_s": [0.1, 0.2, 0.3]} and hash(c) == hash(
        ModelSpec("modified-phong", {"rho_s": np.array([0.1, 0.2, 0.3])}))
    assert a.with_params(n=30).params == {"n": 30.0, "rho_d": 0.1}
    assert a.with_params(n=30) != a


# --------------------------------------------------------------------------- beta
def test_beta_in_degrees_is_the_models_width_parameter():
    s = ModelSpec.parse("modified-phong", ["beta=30"])
    # cosⁿβ = 1/2
    assert s.params == {"n": pytest.approx(-math.log(2.0) / math.log(math.cos(math.radians(30))),
                                           rel=1e-12)}
    # GGX: α² = sin²β / (√2 − cos²β); the width follows the distribution, not the class
    b = math.radians(20.0)
    ggx = ModelSpec.parse("microfacet", ["beta=20", "distribution=ggx"])
    want = math.sqrt(math.sin(b) ** 2 / (math.sqrt(2.0) - math.cos(b) ** 2))
    assert ggx.params["alpha"] == pytest.approx(want, rel=1e-9)
    assert "beta" not in ggx.params and ggx.params["distribution"] == "ggx"
    # the same in a dict (radians, the API's unit), and a width swapped for beta
    assert ModelSpec("modified-phong", {"beta": math.radians(30)}) == s
    assert s.with_params(beta=math.radians(30)) == s
    assert ModelSpec.parse("modified-phong", ["n=5"]).with_params(beta=math.radians(30)) == s


# --------------------------------------------------------------------------- operators
def test_pumped_model_round_trip():
    spec = ModelSpec.parse("modified-phong", ["n=20", "rho_d=0", "rho_s=0.8"], pump="controlled",
                           times=2)
    assert spec.operators == (Operator("pump", (("g", "controlled"), ("times", 2))),)
    assert spec.to_dict() == {"model": "modified-phong",
                              "params": {"n": 20.0, "rho_d": 0.0, "rho_s": 0.8},
                              "pump": {"g": "controlled", "times": 2}}
    m = spec.build()
    by_hand = pump(brdfkit.model("modified-phong", n=20, rho_d=0, rho_s=0.8), "controlled",
                   times=2)
    wi, wo = _pairs()
    want = by_hand.eval(wi, wo)
    np.testing.assert_array_equal(m.eval(wi, wo), want)
    d = m.to_dict()
    assert d["pump"] == {"g": "controlled", "times": 2}
    np.testing.assert_array_equal(ModelSpec.of(m).build().eval(wi, wo), want)
    np.testing.assert_array_equal(pumping_from_dict(d).eval(wi, wo), want)
    # the flat form of the explorer and the Mitsuba plugin: pump = g, times beside it
    flat = ModelSpec.from_dict({"model": "modified-phong", "params": d["params"],
                                "pump": "controlled", "times": 2})
    assert flat == ModelSpec.of(m)
    assert without_pump(flat) == ModelSpec.from_dict({"model": "modified-phong",
                                                      "params": d["params"], "pump": None,
                                                      "times": 1})


def without_pump(spec):
    return spec.without_operators()


def test_stages_with_different_g_round_trip():
    base = brdfkit.model("modified-phong", n=10, rho_d=0, rho_s=0.5)
    m = pump(pump(base, "max"), "controlled")
    d = m.to_dict()
    assert d["pump"] == [{"g": "max", "times": 1}, {"g": "controlled", "times": 1}]
    spec = ModelSpec.of(m)
    assert [o.arguments["g"] for o in spec.operators] == ["max", "controlled"]
    assert spec.to_dict() == d
    wi, wo = _pairs(20)
    np.testing.assert_array_equal(spec.build().eval(wi, wo), m.eval(wi, wo))


def test_compensated_model_round_trip():
    """compensate (issue 22): the dict form, the flat form, of(m).build(), and the order of
    operators kept (compensate, then pump: the dict's keys in the order applied)."""
    spec = ModelSpec.parse("microfacet", ["distribution=ggx", "alpha=0.5"],
                           compensate="kulla-conty", pump="max")
    assert spec.operators == (Operator("compensate", (("method", "kulla-conty"),)),
                              Operator("pump", (("g", "max"), ("times", 1))))
    m = spec.build()
    d = m.to_dict()
    assert list(d) == ["model", "params", "compensate", "pump"]
    assert d["compensate"] == {"method": "kulla-conty"}
    by_hand = pump(brdfkit.compensate(brdfkit.model("microfacet", distribution="ggx",
                                                    alpha=0.5)), "max")
    wi, wo = _pairs(30)
    want = by_hand.eval(wi, wo)
    np.testing.assert_array_equal(m.eval(wi, wo), want)
    np.testing.assert_array_equal(ModelSpec.of(m).build().eval(wi, wo), want)
    t = brdfkit.compensate(brdfkit.model("modified-phong", n=20), "turquin")
    flat = ModelSpec.from_dict({"model": "modified-phong", "params": t.to_dict()["params"],
                                "compensate": "turquin"})
    assert flat == ModelSpec.of(t)
    np.testing.assert_array_equal(flat.build().eval(wi, wo), t.eval(wi, wo))
    assert ModelSpec.from_dict({"model": "lambert", "compensate": None}).operators == ()
    with pytest.raises(BrdfkitError, match="--compensate must be one of kulla-conty, turquin"):
        ModelSpec.parse("lambert", compensate="kc2")
    with pytest.raises(ParameterError, match="compensate: unknown argument 'g'; valid: method"):
        ModelSpec.from_dict({"model": "lambert", "compensate": {"g": "max"}})


def test_pumped_material_rebuilds_from_its_dict():
    """The bug of issue 18: pumping.from_dict resolved names in the model registry only, so
    a pumped material (whose to_dict names merl:…) could not be rebuilt."""
    mat = brdfkit.model("merl:nickel@abc")  # ABC: reciprocal and isotropic, so it pumps
    m = pump(mat, "max")
    d = m.to_dict()
    assert d == {"model": "merl:nickel@abc", "params": {}, "pump": {"g": "max", "times": 1}}
    wi, wo = _pairs(30)
    want = m.eval(wi, wo)
    np.testing.assert_array_equal(pumping_from_dict(d).eval(wi, wo), want)
    spec = ModelSpec.of(m)
    assert spec.kind == "material"
    np.testing.assert_array_equal(spec.build().eval(wi, wo), want)
    assert ModelSpec.parse("merl:nickel@abc", pump="max") == spec


def test_material_specs():
    spec = ModelSpec.parse("MERL:Violet_Rubber")
    assert spec.kind == "material" and spec.name == "merl:violet-rubber"
    m = spec.build()
    assert m is brdfkit.data.material("merl:violet-rubber")  # the catalog's cached object
    assert ModelSpec.of(m).to_dict() == {"model": "merl:violet-rubber", "params": {}}
    assert ModelSpec.of(m).build() is m


def test_merl_file_spec(tmp_path):
    from brdfkit.data.export import export_merl

    path = tmp_path / "lam.binary"
    export_merl(brdfkit.model("lambert", rho_d=0.5), path)
    spec = ModelSpec.parse(path, ["lookup=linear"])
    assert spec.kind == "merl-file" and spec.target == str(path)
    assert spec.to_dict() == {"model": str(path), "params": {"lookup": "linear"}}
    m = spec.build()
    assert m.values["lookup"] == "linear"
    np.testing.assert_allclose(m.eval(*_pairs(5)), 0.5 / math.pi, rtol=1e-3)
    # a built file model's dict keeps only the base name: the error says so
    with pytest.raises(UnknownModelError, match="base name only.*PATH.binary"):
        ModelSpec.of(m).build()


def test_tables_name_every_kind_and_operator():
    assert [k.name for k in KINDS] == ["python-file", "brdf-file", "material", "merl-file", "model"]
    assert list(OPERATORS) == ["pump", "compensate"]
    assert ModelSpec("nickel").kind == "model"  # the fallback claims the rest (then fails)


# --------------------------------------------------------------------------- errors
def test_parse_errors_name_the_argument():
    with pytest.raises(ParameterError, match=r"NAME=VALUE \(e.g. --start rho_d=0.5\); got 'n'"):
        ModelSpec.parse("modified-phong", ["n"], option="--start")
    with pytest.raises(ParameterError, match="modified-phong: parameter 'n' given twice"):
        ModelSpec.parse("modified-phong", ["n=1", "n=2"])
    with pytest.raises(ParameterError, match=r"'beta'.*\(0, 90\); got 95"):
        ModelSpec.parse("modified-phong", ["beta=95"])
    with pytest.raises(ParameterError, match="lambert: has no lobe width"):
        ModelSpec.parse("lambert", ["beta=30"])
    with pytest.raises(BrdfkitError, match="--times 2 needs --pump"):
        ModelSpec.parse("modified-phong", times=2)
    with pytest.raises(BrdfkitError, match="--times must be an integer from 1 to 4; got 9"):
        ModelSpec.parse("modified-phong", pump="max", times=9)
    with pytest.raises(BrdfkitError, match="--pump must be one of max, controlled; got 'up'"):
        ModelSpec.parse("modified-phong", pump="up")
    with pytest.raises(UnknownModelError, match="did you mean the material 'merl:nickel'"):
        ModelSpec.parse("nickel").build()


def test_dict_errors_name_the_key():
    with pytest.raises(ParameterError, match="expected a dict with a 'model' key"):
        ModelSpec.from_dict({"params": {}})
    with pytest.raises(ParameterError, match="unknown key 'pumped'; valid keys: model, params, "
                                             "pump, compensate, times"):
        ModelSpec.from_dict({"model": "lambert", "pumped": "max"})
    with pytest.raises(ParameterError, match="lambert: params must be an object NAME: VALUE"):
        ModelSpec.from_dict({"model": "lambert", "params": [1, 2]})
    with pytest.raises(ParameterError, match="pump must be 'max', 'controlled' or none; got 'up'"):
        ModelSpec.from_dict({"model": "lambert", "pump": "up"})
    with pytest.raises(ParameterError, match="times must be an integer from 1 to 4; got 0"):
        ModelSpec.from_dict({"model": "lambert", "pump": {"g": "max", "times": 0}})
    with pytest.raises(ParameterError, match="pump: unknown argument 'k'; valid: g, times"):
        ModelSpec.from_dict({"model": "lambert", "pump": {"g": "max", "k": 2}})
    with pytest.raises(ParameterError, match="a custom g cannot be rebuilt"):
        ModelSpec.from_dict({"model": "lambert", "pump": {"g": "custom", "times": 1}})
    with pytest.raises(ParameterError, match="unknown operator 'smooth'; valid: pump, "
                                             "compensate"):
        Operator("smooth")
    assert Operator("compensate").arguments == {"method": "kulla-conty"}  # the default
    with pytest.raises(ParameterError, match="expected a brdfkit model"):
        ModelSpec.of({"model": "lambert"})
    with pytest.raises(ParameterError, match="model must be a model name"):
        ModelSpec(3)
    with pytest.raises(ParameterError, match="unknown parameter 'q'"):
        ModelSpec.from_dict({"model": "lambert", "params": {"q": 1}}).build()


def test_properties_form():
    spec = ModelSpec.from_properties({"model": "diffuse", "rho_d": "0.1, 0.4, 0.7"})
    assert spec == ModelSpec.parse("diffuse", ["rho_d=0.1,0.4,0.7"])
    pumped = ModelSpec.from_properties({"model": "modified-phong", "n": 20, "pump": "max",
                                        "times": 2})
    assert pumped == ModelSpec.parse("modified-phong", ["n=20"], pump="max", times=2)
    with pytest.raises(ParameterError, match='brdfkit plugin: property "model" is required'):
        ModelSpec.from_properties({"n": 20})
    with pytest.raises(ParameterError, match="property 'k' must be a number, a word or a "
                                             "comma-separated list"):
        ModelSpec.from_properties({"model": "microfacet", "k": "1, x"})


# --------------------------------------------------------------------------- the users
def test_batch_jobs_and_explorer_entries_are_specs():
    from brdfkit.explorer.app import entry_spec
    from brdfkit.fitting.batch import Job, job_spec

    want = ModelSpec.parse("modified-phong", ["n=20"], pump="controlled")
    job = Job("modified-phong", "merl:nickel",
              options=(("params", '{"n": 20}'), ("pump", "controlled"), ("seed", 0),
                       ("times", 1)))
    assert job_spec(job) == want
    assert job_spec(Job("nielsen", "merl:nickel")) == ModelSpec("nielsen")
    entry = {"spec": "modified-phong", "params": {"n": 20, "rho_d": ""}, "pump": "controlled",
             "times": 1, "visible": True}
    assert entry_spec(entry) == want
    assert entry_spec({"spec": "modified-phong", "params": {"beta": 30}, "pump": None,
                       "times": 1}) == ModelSpec.parse("modified-phong", ["beta=30"])
    assert entry_spec({"spec": "modified-phong", "params": {"n": 20}, "compensate": "turquin",
                       "pump": None}) == ModelSpec.parse("modified-phong", ["n=20"],
                                                         compensate="turquin")


def test_mitsuba_plugin_properties_are_the_spec_vocabulary():
    """The plugin's properties: "pump" is g and "times" K, as everywhere; the old "pump": N
    (N times) with "pump_g" is still read, and mixing the two forms is one clear error."""
    from brdfkit.render.mitsuba_plugin import _model_from_props

    wi, wo = _pairs(10)
    new, lam = _model_from_props({"model": "modified-phong", "n": 20, "pump": "controlled",
                                  "times": 1, "id": "x", "wavelengths": "450, 550"})
    old, _ = _model_from_props({"model": "modified-phong", "n": 20, "pump": 1,
                                "pump_g": "controlled"})
    assert new.stages == old.stages == ["controlled"]
    np.testing.assert_array_equal(new.eval(wi, wo), old.eval(wi, wo))
    np.testing.assert_array_equal(lam, [450.0, 550.0])
    plain, _ = _model_from_props({"model": "lambert", "pump": 0})
    assert plain.name == "lambert"
    with pytest.raises(ParameterError, match='give "pump": "max"|"controlled" with "times"'):
        _model_from_props({"model": "lambert", "pump": 2, "times": 2})
    with pytest.raises(ParameterError, match="not both"):
        _model_from_props({"model": "lambert", "pump": "max", "pump_g": "max"})
