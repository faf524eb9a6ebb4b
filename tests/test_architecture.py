"""The layering of docs/architecture.md, enforced on the source.

- A module imports only from its own layer and the layers below (imports inside
  functions count too).
- No brdfkit module is imported inside ``try/except ImportError`` (self-guarding).
- No source file over 600 lines (issue 18: modules by concept), without exceptions.
- No engine probes a model with getattr/hasattr for a protocol hook.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "brdfkit"

#: docs/architecture.md, "Layers"
LAYER = {
    "errors": 0, "_array": 0, "_kern": 0, "geometry": 0, "fresnel": 0, "halfangle": 0,
    "tables": 0, "_io": 0, "_dual": 0, "status": 0, "_cache": 0, "_threads": 0, "colour": 0,
    # glsl: the .brdf files' GLSL → formula source (issue 21; a translator, no models)
    "glsl": 0,
    # traced_tables: the Dr.Jit side of tables' lookups (issue 23)
    "traced_tables": 0,
    # the package root is the public facade (brdfkit.model resolves model names and
    # material specs; brdfkit.spec builds a ModelSpec, applying its operators): layer 2,
    # so the data layer and the operators (pumping) are beside it and cli/figures above
    "": 2, "spec": 2, "models": 1,
    "analysis": 2, "data": 2, "pumping": 2,
    # compensation: the second operator beside pumping (issue 22), reusing pumping's albedo
    # table builder; spec_operators: the spec's operator registry (moved out of spec)
    "compensation": 2, "spec_operators": 2,
    # user: models from the user's own files (.py, .brdf), built on models/ and data/
    # (the tabulated sampler); formula: what a user's .py file imports (layer 1: _dual and
    # Param); spec_words: the spec's NAME=VALUE parsing
    "user": 2, "formula": 1, "spec_words": 2,
    "fitting": 3, "render": 3,
    "figures": 4, "cli": 4, "report": 4, "explorer": 4, "__main__": 4,
}
#: Packages of layer 2 that the table of docs/architecture.md restricts further: they import
#: layers 0–1 only (and themselves), not the rest of their own layer — analysis does not
#: know materials (data), operators or specs; data (measured materials) knows neither the
#: analyses nor the user's models (the proxy sampler its formulas use is models/, layer 1)
BELOW_ONLY = {"analysis": 1, "data": 1}
MAX_LINES = 600
#: hooks of the model protocol that must be read as declared attributes, never probed
HOOKS = {"isotropic", "specular_albedo", "albedo_kinks", "albedo_kinks_nv", "albedo_kink_mus",
         "has_delta", "has_sampler", "lobes", "sharpest_lobe", "kernel", "packed", "n_channels",
         "reciprocal", "sample", "pdf", "to_dict", "formulas", "fit_gauge", "fit_base",
         "fit_bound_starts", "fresnel_split"}


def _modules():
    return sorted(p for p in SRC.rglob("*.py"))


def _top(path: Path) -> str:
    rel = path.relative_to(SRC).with_suffix("")
    parts = rel.parts
    if parts == ("__init__",):
        return ""
    return parts[0]


def _imported_tops(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "brdfkit" or a.name.startswith("brdfkit."):
                    yield node, (a.name.split(".") + [""])[1]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "brdfkit":
                # `from brdfkit import x`: x is a subpackage/module or a root re-export
                for a in node.names:
                    yield node, a.name if a.name in LAYER else ""
            elif node.module.startswith("brdfkit."):
                yield node, node.module.split(".")[1]


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(SRC)))
def test_imports_go_down_only(path):
    top = _top(path)
    assert top in LAYER, f"{path}: module {top!r} is in no layer of docs/architecture.md"
    tree = ast.parse(path.read_text())
    for node, other in _imported_tops(tree):
        assert other in LAYER, f"{path}:{node.lineno}: imports unknown brdfkit.{other}"
        assert LAYER[other] <= LAYER[top], (
            f"{path}:{node.lineno}: layer {LAYER[top]} ({top or 'brdfkit'}) imports "
            f"brdfkit.{other} of layer {LAYER[other]} (docs/architecture.md)")
        if top in BELOW_ONLY and other != top:
            assert LAYER[other] <= BELOW_ONLY[top], (
                f"{path}:{node.lineno}: {top} imports brdfkit.{other or '(the root)'}; it "
                f"may import layers 0-{BELOW_ONLY[top]} only (docs/architecture.md)")


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(SRC)))
def test_no_self_guarding_imports(path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if not isinstance(node, ast.Try):
            continue
        catches_import_error = any(
            h.type is not None and "ImportError" in ast.unparse(h.type) for h in node.handlers)
        if not catches_import_error:
            continue
        for inner in node.body:
            for sub in ast.walk(inner):
                if isinstance(sub, ast.Import | ast.ImportFrom):
                    names = ([a.name for a in sub.names] if isinstance(sub, ast.Import)
                             else [sub.module or ""])
                    assert not any(n.startswith("brdfkit") for n in names), (
                        f"{path}:{sub.lineno}: brdfkit module imported inside "
                        "try/except ImportError")


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(SRC)))
def test_source_files_are_not_too_long(path):
    n = len(path.read_text().splitlines())
    assert n <= MAX_LINES, (f"{path} has {n} lines (> {MAX_LINES}): split it (one module "
                            "per concept)")


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(SRC)))
def test_protocol_hooks_are_not_probed(path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("getattr", "hasattr") and len(node.args) >= 2
                and isinstance(node.args[1], ast.Constant)):
            assert node.args[1].value not in HOOKS, (
                f"{path}:{node.lineno}: {node.func.id}(..., {node.args[1].value!r}) probes a "
                "declared protocol hook; read the attribute (models.BRDF declares it)")


def test_no_name_shadows_a_module():
    # e.g. the function brdfkit.analysis.albedo once shadowed the module of the same name
    import importlib
    import pkgutil

    for init in SRC.rglob("__init__.py"):
        pkg_name = ".".join(("brdfkit", *init.parent.relative_to(SRC).parts))
        pkg = importlib.import_module(pkg_name)
        for info in pkgutil.iter_modules([str(init.parent)]):
            attr = pkg.__dict__.get(info.name)
            if attr is None:
                continue
            assert getattr(attr, "__name__", None) == f"{pkg_name}.{info.name}", (
                f"{pkg_name}.{info.name} is {attr!r}, which shadows the module of that name")
