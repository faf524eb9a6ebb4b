"""
The model spec: what to build, its parameters, the operators applied to it
==========================================================================

One immutable value, :class:`ModelSpec`, says which model to build, with which
parameters and which operators applied to it in order. Every place that builds
a model from words (the command line's ``MODEL -p NAME=VALUE --pump G --times
K``, the Mitsuba plugin's properties) or from a dict (``model.to_dict()``, the
explorer's state entries, the fitting batches' jobs and the study's rows) goes
through it, so a model is described one way everywhere:

- :meth:`ModelSpec.parse` — from the command line's words;
- :meth:`ModelSpec.from_dict` / :meth:`ModelSpec.to_dict` — the JSON form that
  ``model.to_dict()`` produces, ``{"model": NAME, "params": {...},
  "pump": {"g": G, "times": K}}`` (a list of such for stages with different g);
- :meth:`ModelSpec.from_properties` — a flat property list (the Mitsuba plugin:
  ``{"model": NAME, "pump": G, "times": K, PARAM: VALUE, …}``);
- :meth:`ModelSpec.of` — the spec of a built model (``of(m).build()`` has its values);
- :meth:`ModelSpec.build` — the model.

What to build (:data:`KINDS`, the first kind that claims the name builds it): the
model a user's Python file defines, ``PATH.py`` or ``PATH.py:NAME``
(:mod:`brdfkit.user.python_file`); a BRDF Explorer file ``PATH.brdf``
(:mod:`brdfkit.user.brdf_file`), both built as :class:`~brdfkit.user.model.FormulaBRDF`; a
built-in measured material ``merl:NAME[@nbrdf|npf|abc|sgd]``, ``rgl:NAME``,
``nielsen:NAME`` (:func:`brdfkit.data.material`; no parameters); a MERL file
``PATH.binary`` (:class:`~brdfkit.data.MeasuredBRDF`, parameter ``lookup``); else a
registered model name or alias (:data:`brdfkit.MODELS`).

Operators (:data:`OPERATORS`, :mod:`brdfkit.spec_operators`; applied in the order
given): ``pump`` with ``g`` (``max``, ``controlled``) and ``times`` (1 …
:data:`MAX_TIMES`), that is :func:`brdfkit.pumping.pump` (Neumann et al. 1999, eqs.
16–21); ``compensate`` with ``method`` (``kulla-conty``, ``turquin``), that is
:func:`brdfkit.compensation.compensate`.

A half-angle ``beta`` among the parameters (degrees on the command line,
radians in a dict) is resolved once, when the spec is made, into the model's
width parameter (``n``, ``alpha``, ``m`` … as the model and its distribution
say): a spec's parameters are always the model's own.

An unknown name raises :class:`~brdfkit.errors.UnknownModelError` listing the
valid model names and the material-spec forms, with did-you-mean hints for
both (``nickel`` → ``merl:nickel``).

This module is the package root's (layer 2 in ``docs/architecture.md``, with
``data`` and ``pumping``, whose operator it applies); ``docs/architecture.md``,
"Model spec", says how to add a kind or an operator.

Public objects
--------------
- :class:`ModelSpec`, :class:`Operator` — the spec and one applied operator.
- :func:`model` — build a model or a material from its name (``brdfkit.model``).
- :func:`model_params` — the parameter declarations a name accepts.
- :func:`canonical_name` — a name's canonical name.
- :func:`parse_items`, :func:`property_value` — ``NAME=VALUE`` words, a flat property → values.
- :func:`times_problem` — why a number of pumpings is invalid, or None.
- :func:`is_material_spec` — whether a name is a material spec.
- :data:`KINDS`, :class:`SpecKind`; :data:`OPERATORS`, :class:`OperatorKind`.
- :data:`SPEC_FORMS`, :data:`PUMP_CHOICES`, :data:`MAX_TIMES`, :data:`TIMES_REASON`,
  :data:`COMPENSATE_CHOICES` (the compensation methods).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from brdfkit.data.catalog import (
    MATERIAL_SOURCES,
    is_material_spec,
    material,
    suggest_material_specs,
)
from brdfkit.errors import BrdfkitError, ParameterError, UnknownModelError
from brdfkit.models import BRDF, resolve
from brdfkit.spec_operators import (
    OPERATORS,
    TIMES_REASON,
    OperatorKind,
    _compensation,
    _pumping,
    times_problem,
)
from brdfkit.spec_words import parse_words, property_value

__all__ = ["ModelSpec", "Operator", "model", "model_params", "canonical_name", "parse_items",
           "property_value", "times_problem", "is_material_spec", "KINDS", "SpecKind", "OPERATORS",
           "OperatorKind", "SPEC_FORMS", "PUMP_CHOICES", "MAX_TIMES",  # noqa: F822 (lazy)
           "COMPENSATE_CHOICES",  # noqa: F822 (lazy)
           "TIMES_REASON"]

#: How a material spec is written (for error messages and help texts).
SPEC_FORMS = ("merl:NAME[@nbrdf|@npf|@abc|@sgd], rgl:NAME, nielsen:NAME or a path to a "
              "MERL .binary file ('brdfkit materials' lists the built-in ones)")
def __getattr__(name: str):
    if name == "COMPENSATE_CHOICES":
        return tuple(_compensation().METHODS)
    if name in ("PUMP_CHOICES", "MAX_TIMES"):
        return tuple(_pumping().G_CHOICES) if name == "PUMP_CHOICES" else _pumping().MAX_TIMES
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# --------------------------------------------------------------------------- what to build
@dataclass(frozen=True)
class SpecKind:
    """One kind of thing a spec builds.

    ``claims(name)`` says whether a name is of this kind; ``resolve(name)`` gives
    a template with ``.name`` (canonical) and ``.params`` (declarations) — a model
    class or a model object — and ``build(template, params)`` the model; ``draft(name)``,
    when not None, a template built the same way that compiles nothing (interpreted models:
    the explorer draws them while ``resolve`` compiles; ``docs/architecture.md``).
    """

    name: str
    form: str
    claims: Callable[[object], bool]
    resolve: Callable[[object], object]
    build: Callable[[object, dict], BRDF]
    draft: Callable[[object], object] | None = None


def _unknown(name, err: UnknownModelError) -> UnknownModelError:
    hints = suggest_material_specs(str(name))
    hint = (" (did you mean the material " + " or ".join(repr(h) for h in hints) + "?)"
            if hints else "")
    return UnknownModelError(f"{err}{hint}; or a material spec: {SPEC_FORMS}")


def _registered(name):
    try:
        return resolve(name)
    except UnknownModelError as err:
        raise _unknown(name, err) from None


def _is_builtin(name) -> bool:
    source, sep, _ = str(name).strip().partition(":") if isinstance(name, str) else ("", "", "")
    return bool(sep) and source.lower() in MATERIAL_SOURCES


def _is_merl_file(name) -> bool:
    if isinstance(name, os.PathLike):
        return True
    s = str(name).strip().lower() if isinstance(name, str) else ""
    return s.endswith(".binary") or s.startswith("merl-file:")


def _merl_file(name):
    if isinstance(name, str) and name.strip().lower().startswith("merl-file:"):
        raise UnknownModelError(
            f"{name!r} names a MERL file by its base name only (what the model's to_dict "
            "keeps); give the file's path, PATH.binary")
    return material(name)


def _with_params(template, params: dict):
    return template.with_params(**params) if params else template


def _path_text(name) -> str:
    return os.fspath(name).strip() if isinstance(name, str | os.PathLike) else ""


def _is_python_file(name) -> bool:
    s = _path_text(name)
    head, sep, tail = s.rpartition(":")
    return s.lower().endswith(".py") or bool(sep and head.lower().endswith(".py")
                                             and tail.isidentifier())


def _is_brdf_file(name) -> bool:
    return _path_text(name).lower().endswith(".brdf")


# the user's files are read on first use (brdfkit.user: its loaders, Numba, the tabulated
# sampler), not with the package
def _python_definition(name, compiled: bool = True):
    from brdfkit.user.python_file import definition
    return definition(_path_text(name), compiled=compiled)


def _brdf_definition(name, compiled: bool = True):
    from brdfkit.user.brdf_file import definition
    return definition(_path_text(name), compiled=compiled)


def _user_model(definition, params: dict) -> BRDF:
    from brdfkit.user.model import FormulaBRDF
    return FormulaBRDF(definition, **params)


#: What a spec builds, tried in order; the registered models claim every other name.
#: A new kind is one entry before the last; the user's files come first (a path object
#: naming a ``.py``/``.brdf`` file is theirs, any other path a MERL file's).
KINDS: tuple[SpecKind, ...] = (
    SpecKind("python-file", "PATH.py or PATH.py:NAME (a model written in Python)",
             _is_python_file, _python_definition, _user_model,
             lambda name: _python_definition(name, compiled=False)),
    SpecKind("brdf-file", "PATH.brdf (a BRDF Explorer file)", _is_brdf_file, _brdf_definition,
             _user_model, lambda name: _brdf_definition(name, compiled=False)),
    SpecKind("material", "merl:NAME[@nbrdf|@npf|@abc|@sgd], rgl:NAME, nielsen:NAME",
             _is_builtin, material, _with_params),
    SpecKind("merl-file", "PATH.binary (a MERL file)", _is_merl_file, _merl_file, _with_params),
    SpecKind("model", "a registered model name or alias ('brdfkit models')",
             lambda name: True, _registered, lambda cls, params: cls(**params)),
)


def _kind(name) -> SpecKind:
    return next(k for k in KINDS if k.claims(name))


def model(name, /, **params) -> BRDF:
    """Build the model or material called *name* (module docstring) with *params*.

    *name*: a registered model name or alias, a built-in material spec, a path to a
    MERL ``.binary`` file, a user's ``PATH.py[:NAME]`` or ``PATH.brdf``; *params* in API
    units (``beta`` in radians), omitted ones at their defaults (built-in materials have
    none; a ``.binary`` file has ``lookup``).

    Raises
    ------
    UnknownModelError
        *name* is neither a model nor a material; the message lists both.
    ParameterError
        A parameter the model does not declare, or a value outside its bounds.
    DataFileError
        A ``.binary`` path that cannot be read, a user's file that is malformed.

    Examples
    --------
    >>> import brdfkit
    >>> m, nickel = brdfkit.model("modified-phong", rho_s=0.5, n=50), brdfkit.model("merl:nickel")
    """
    kind = _kind(name)
    return kind.build(kind.resolve(name), params)


def model_params(name) -> tuple:
    """The parameter declarations (:class:`~brdfkit.Param`) *name* accepts."""
    return tuple(_kind(name).resolve(name).params)


def canonical_name(name) -> str:
    """The canonical name of a registered model, or the material's own name."""
    return _kind(name).resolve(name).name


# --------------------------------------------------------------------------- words
def parse_items(name, items: Iterable[str] | Mapping, *, option: str = "-p") -> dict:
    """``NAME=VALUE`` words (as typed after *option*) → parameter values for *name*.

    Numbers; comma-separated numbers for per-channel colour or per-lobe
    parameters; words for choice and bool parameters; ``none`` for optional ones;
    ``beta`` in degrees, in (0, 90), converted to radians
    (:func:`brdfkit.spec_words.parse_words`). A mapping is taken as already parsed
    (API units) and returned as a dict. A name the model does not declare is kept
    as text: the model names it and lists the valid ones.

    Raises
    ------
    UnknownModelError
        *name* is neither a model nor a material.
    ParameterError
        A malformed item (naming *option*), a repeated name, or a value that is
        not a number.
    """
    template = _kind(name).resolve(name)
    if isinstance(items, Mapping):
        return dict(items)
    return parse_words(template.name, template.params, items, option=option)


#: The dict form's keys: the target, its parameters, each operator and its flat siblings.
_DICT_KEYS = ("model", "params", *OPERATORS, *(s for o in OPERATORS.values() for s in o.flat))


@dataclass(frozen=True)
class Operator:
    """One operator applied to a model: ``kind`` (a key of :data:`OPERATORS`) and its
    ``args`` as sorted ``(name, value)`` pairs (:attr:`arguments` as a dict)."""

    kind: str
    args: tuple = ()

    def __post_init__(self):
        if self.kind not in OPERATORS:
            raise ParameterError(f"unknown operator {self.kind!r}; valid: "
                                 + ", ".join(OPERATORS))
        checked = OPERATORS[self.kind].check(dict(self.args))
        object.__setattr__(self, "args", tuple(sorted(checked.items())))

    @property
    def arguments(self) -> dict:
        return dict(self.args)


# --------------------------------------------------------------------------- the spec
def _freeze(v):
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, list | tuple):
        return tuple(_freeze(x) for x in v)
    return v.item() if isinstance(v, np.generic) else v


def _thaw(v):
    return [_thaw(x) for x in v] if isinstance(v, tuple) else v


class ModelSpec:
    """What to build, its parameters and the operators applied to it (module docstring).

    Parameters
    ----------
    target : str or os.PathLike
        A registered name or alias, a material spec or a MERL file path (:data:`KINDS`).
    params : mapping, optional
        Parameter values in API units (``beta`` in radians is resolved into the
        model's width parameter here, which builds the model once).
    operators : sequence of Operator, optional
        Applied in order by :meth:`build`.

    A spec is immutable and hashable; two specs are equal when they name the
    same target with the same parameters and operators. :attr:`params` is a
    fresh dict (lists for per-channel values).

    Examples
    --------
    >>> from brdfkit.spec import ModelSpec
    >>> s = ModelSpec.parse("modified-phong", ["n=20"], pump="max", times=2)
    >>> s.to_dict()
    {'model': 'modified-phong', 'params': {'n': 20.0}, 'pump': {'g': 'max', 'times': 2}}
    >>> m = s.build()
    """

    __slots__ = ("_target", "_params", "_operators")

    def __init__(self, target, params: Mapping | None = None, operators: Iterable = ()):
        if not isinstance(target, str | os.PathLike):
            raise ParameterError(f"model must be a model name or a material spec (a string); "
                                 f"got {type(target).__name__} {target!r}")
        target = os.fspath(target) if isinstance(target, os.PathLike) else target.strip()
        params = {} if params is None else params
        if not isinstance(params, Mapping):
            raise ParameterError(f"{target}: params must be an object NAME: VALUE; got "
                                 f"{params!r}")
        ops = tuple(operators)
        bad = [o for o in ops if not isinstance(o, Operator)]
        if bad:
            raise ParameterError(f"{target}: operators must be Operator values; got {bad[0]!r}")
        params = dict(params)
        if "beta" in params:  # the half-angle → the model's own width parameter, once
            kind = _kind(target)
            m = kind.build(kind.resolve(target), params)
            del params["beta"]
            params[m.width_param] = m.values[m.width_param]
        object.__setattr__(self, "_target", target)
        object.__setattr__(self, "_params",
                           tuple(sorted((str(k), _freeze(v)) for k, v in params.items())))
        object.__setattr__(self, "_operators", ops)

    def __setattr__(self, name, value):
        raise AttributeError("a ModelSpec is immutable: use with_params or a new spec")

    # --------------------------------------------------------------- accessors
    @property
    def target(self) -> str:
        """The name as given (a registered name or alias, a material spec, a path)."""
        return self._target

    @property
    def params(self) -> dict:
        """The parameter values (a new dict; lists for per-channel/per-lobe values)."""
        return {k: _thaw(v) for k, v in self._params}

    @property
    def operators(self) -> tuple:
        """The operators, in the order :meth:`build` applies them."""
        return self._operators

    @property
    def kind(self) -> str:
        """The :data:`KINDS` entry that builds the target (``model``, ``material`` …)."""
        return _kind(self._target).name

    @property
    def name(self) -> str:
        """The target's canonical name (:func:`canonical_name`)."""
        return canonical_name(self._target)

    def _key(self) -> tuple:
        return (self._target, self._params, self._operators)

    def __eq__(self, other):
        return self._key() == other._key() if isinstance(other, ModelSpec) else NotImplemented

    def __hash__(self):
        return hash(self._key())

    def __repr__(self):
        ops = "".join(f", {o.kind}({', '.join(f'{k}={v!r}' for k, v in o.args)})"
                      for o in self._operators)
        return f"ModelSpec({self._target!r}, {self.params!r}{ops})"

    # --------------------------------------------------------------- variants
    def with_params(self, **changes) -> ModelSpec:
        """The same spec with some parameters changed (``beta`` replaces the width)."""
        params = self.params
        if "beta" in changes:
            kind = _kind(self._target)
            params.pop(kind.build(kind.resolve(self._target), params).width_param, None)
        return ModelSpec(self._target, {**params, **changes}, self._operators)

    def without_operators(self) -> ModelSpec:
        """The spec of the model the operators apply to."""
        return ModelSpec(self._target, self.params)

    # --------------------------------------------------------------- build
    def build(self) -> BRDF:
        """The model: the target built with the parameters, then each operator applied."""
        m = model(self._target, **self.params)
        for op in self._operators:
            m = OPERATORS[op.kind].apply(m, op.arguments)
        return m

    # --------------------------------------------------------------- words
    @classmethod
    def parse(cls, target, params: Iterable[str] | Mapping = (), pump: str | None = None,
              times: int | None = None, *, option: str = "-p",
              compensate: str | None = None) -> ModelSpec:
        """The spec of the command line's ``MODEL -p NAME=VALUE … --compensate M --pump G
        --times K``: *target* a name of :data:`KINDS`; *params* ``NAME=VALUE`` words or a
        mapping (:func:`parse_items`: ``beta`` in degrees); *compensate* None or a method
        (:func:`brdfkit.compensation.compensate`), applied first; *pump* None, ``"max"``
        or ``"controlled"`` (:func:`brdfkit.pumping.pump`) applied *times* times (1 …
        :data:`MAX_TIMES`, default 1; only with *pump*); *option* is named in the error for
        a malformed item. Raises :class:`BrdfkitError` for an unknown model, a bad
        parameter or method, *times* out of range or *times* without *pump* (it would be
        ignored).
        """
        values = parse_items(target, params, option=option)
        if pump is None and times is not None:
            raise BrdfkitError(f"--times {times} needs --pump max or --pump controlled (it says "
                               "how many times to pump); add --pump or drop --times")
        ops: tuple = ()
        if compensate is not None:
            methods = _compensation().METHODS
            if compensate not in methods:
                raise BrdfkitError(f"--compensate must be one of {', '.join(methods)}; got "
                                   f"{compensate!r}")
            ops = (Operator("compensate", (("method", compensate),)),)
        if pump is not None:
            times = 1 if times is None else times
            problem = times_problem(times)
            if problem is not None:
                raise BrdfkitError(f"--times {problem}")
            choices = _pumping().G_CHOICES
            if pump not in choices:
                raise BrdfkitError(f"--pump must be one of {', '.join(choices)}; got {pump!r}")
            ops = ops + (Operator("pump", (("g", pump), ("times", int(times)))),)
        return cls(target, values, ops)

    @classmethod
    def from_properties(cls, props: Mapping, *, where: str = "brdfkit plugin") -> ModelSpec:
        """The spec of a flat property list (the Mitsuba plugin's scene-dict properties):
        ``{"model": NAME, PARAM: VALUE, …, "pump": G, "times": K}``, values in API units
        (:func:`property_value`: ``"eta": "0.2, 0.9, 1.1"``); *where* prefixes the errors."""
        if "model" not in props:
            raise ParameterError(
                f'{where}: property "model" is required (a model name such as '
                '"modified-phong" or a material spec such as "merl:nickel")')
        spec = {"model": str(props["model"]), "params": {}}
        for key, value in props.items():
            if key in _DICT_KEYS:
                spec.setdefault(key, value)
                continue
            spec["params"][key] = property_value(key, value, where=where)
        return cls.from_dict(spec)

    # --------------------------------------------------------------- dicts
    @classmethod
    def from_dict(cls, d: Mapping) -> ModelSpec:
        """The spec of the dict form (:meth:`to_dict`; what ``model.to_dict()`` gives).

        ``{"model": NAME, "params": {...}}`` plus, per operator of
        :data:`OPERATORS` in the order applied, its key: ``"pump": {"g": G,
        "times": K}``, a list of those, or the flat ``"pump": G`` with
        ``"times": K`` beside it; ``"compensate": {"method": M}`` or the flat
        ``"compensate": M`` (``None``/``"none"``: not applied).

        Raises
        ------
        ParameterError
            Not a dict with a ``model`` key, an unknown key, or an operator's
            bad argument (named).
        """
        if not isinstance(d, Mapping) or "model" not in d:
            raise ParameterError(f"from_dict: expected a dict with a 'model' key; got {d!r}")
        unknown = [k for k in d if k not in _DICT_KEYS]
        if unknown:
            raise ParameterError(f"from_dict: unknown key {unknown[0]!r}; valid keys: "
                                 + ", ".join(_DICT_KEYS))
        ops = [Operator(key, tuple(dict(stage).items()))
               for key in d if key in OPERATORS
               for stage in OPERATORS[key].stages(d[key], d)]
        return cls(d["model"], d.get("params") or {}, ops)

    def to_dict(self) -> dict:
        """``{"model": target, "params": {...}}`` plus each operator's key (in order):
        the form ``model.to_dict()`` has, which :meth:`from_dict` reads."""
        d: dict = {"model": self._target, "params": self.params}
        runs: list = []  # consecutive operators of one kind
        for op in self._operators:
            if runs and runs[-1][0] == op.kind:
                runs[-1][1].append(op.arguments)
            else:
                runs.append((op.kind, [op.arguments]))
        for kind, stages in runs:
            if kind in d:
                raise ParameterError(
                    f"to_dict: the {kind} operator recurs after another operator; the dict "
                    "form keeps one key per operator kind")
            d[kind] = OPERATORS[kind].value(stages)
        return d

    @classmethod
    def of(cls, built: BRDF) -> ModelSpec:
        """The spec of a built model (from its ``to_dict()``): ``of(m).build()`` has
        ``m``'s values, for every registered, material, pumped and compensated model."""
        if not isinstance(built, BRDF):
            raise ParameterError(f"ModelSpec.of: expected a brdfkit model (BRDF); got "
                                 f"{type(built).__name__}")
        return cls.from_dict(built.to_dict())
