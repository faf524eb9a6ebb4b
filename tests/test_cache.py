"""One cache policy (brdfkit._cache): bounded, registered, clearable.

References by construction: a memo's evaluations are counted (a hit does not call the
function, an evicted key calls it again), least-recently-used order is checked against
the sequence of calls, and the source scan compares the registry with what the modules
define.
"""

from __future__ import annotations

import ast
import gc
import importlib
import pkgutil
from pathlib import Path

import pytest

import brdfkit
from brdfkit import _cache
from brdfkit._cache import CACHES, BoundedCache, bounded_cache, cache_info, clear_caches, memo
from brdfkit.errors import ParameterError

SRC = Path(__file__).resolve().parents[1] / "src" / "brdfkit"

#: Module-level containers that are registries filled once (at import or by decorators),
#: not caches: they never grow with use and clearing them would break the program.
REGISTRIES = {
    ("models/_registry.py", "MODELS"): "the model registry (@register)",
    ("models/_registry.py", "_ALIASES"): "aliases of registered models",
    ("_dual.py", "_FORMULAS"): "every @formula (import time)",
    ("_dual.py", "_PRIMITIVES"): "every @primitive (import time)",
    ("_cache.py", "CACHES"): "the cache registry itself",
}
#: Calls that make an ad-hoc cache; brdfkit._cache is the one place allowed to use them.
AD_HOC = ("functools.cache", "functools.lru_cache", "lru_cache", "cache", "cached_property",
          "functools.cached_property", "OrderedDict", "collections.OrderedDict",
          "weakref.WeakKeyDictionary", "WeakKeyDictionary", "weakref.WeakValueDictionary",
          "WeakValueDictionary")


@pytest.fixture
def scratch():
    """Names registered by a test, removed after it (the registry is process-wide)."""
    names: list[str] = []
    yield names
    for n in names:
        CACHES.pop(n, None)


def test_memo_counts_and_bounds(scratch):
    calls = []

    @memo(maxsize=3, name="test.square")
    def square(x):
        calls.append(x)
        return x * x

    scratch.append("test.square")
    assert [square(x) for x in (1, 2, 3, 1)] == [1, 4, 9, 1]
    assert calls == [1, 2, 3]  # the second 1 is a hit
    square(4)  # evicts the least recently used: 2 (1 was just used)
    assert len(square.cache) == 3
    square(1)
    square(3)
    assert calls == [1, 2, 3, 4]
    square(2)  # evicted: computed again
    assert calls == [1, 2, 3, 4, 2]
    info = square.cache.info()
    assert (info.size, info.maxsize, info.hits, info.misses) == (3, 3, 3, 5)
    # keyword arguments are part of the key, distinct from positional ones
    assert square(x=5) == 25 and calls[-1] == 5


def test_bounded_cache_evicts_least_recent(scratch):
    c = bounded_cache("test.dict", maxsize=2)
    scratch.append("test.dict")
    c["a"] = 1
    c["b"] = 2
    assert c.get("a") == 1  # a is now the most recent
    c["c"] = 3
    assert "b" not in c and "a" in c and "c" in c and len(c) == 2
    assert c.setdefault("a", 9) == 1 and c.setdefault("d", [4]) == [4]
    assert "c" not in c  # d evicted c (a was read by setdefault)
    assert c.pop("a") == 1 and c.pop("a", "gone") == "gone"
    del c["d"]
    assert len(c) == 0
    with pytest.raises(KeyError):
        c["missing"]


def test_clear_caches_clears_every_registered_cache(scratch):
    @memo(maxsize=4, name="test.clear.f")
    def f(x):
        return x

    d = bounded_cache("test.clear.d", maxsize=4)
    per_object = bounded_cache(None, maxsize=4)
    scratch += ["test.clear.f", "test.clear.d"]
    f(1)
    f(2)
    d["k"] = 1
    per_object["k"] = 1
    assert clear_caches("test.clear.") == 3
    assert len(f.cache) == 0 and len(d) == 0 and len(per_object) == 1
    assert clear_caches("<per-object>") >= 1 and len(per_object) == 0
    # the public entry clears everything, the library's caches included
    brdfkit.material("merl:nickel")
    assert len(CACHES["brdfkit.data.catalog._build"]) >= 1
    brdfkit.clear_caches()
    assert all(i.size == 0 for i in cache_info())
    assert brdfkit.material("merl:nickel").name == "merl:nickel"  # rebuilt on demand


def test_weak_keys_go_with_their_object(scratch):
    class Key:
        pass

    c = bounded_cache("test.weak", maxsize=8, weak=True)
    scratch.append("test.weak")
    k1, k2 = Key(), Key()
    c[k1] = "one"
    c[k2] = "two"
    assert c.get(k1) == "one" and len(c) == 2
    del k1
    gc.collect()
    assert len(c) == 1 and c.get(k2) == "two"


def test_errors_name_the_cache_and_the_value(scratch):
    with pytest.raises(ParameterError, match=r"'test.bad': maxsize must be an integer >= 1; "
                                             r"got 0"):
        BoundedCache("test.bad", maxsize=0)
    bounded_cache("test.twice", maxsize=1)
    scratch.append("test.twice")
    with pytest.raises(ParameterError, match="'test.twice' is already registered"):
        bounded_cache("test.twice", maxsize=1)


# --------------------------------------------------------------------------- the source scan
def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def _sources():
    return sorted(p for p in SRC.rglob("*.py") if p.name != "_cache.py")


@pytest.mark.parametrize("path", _sources(), ids=lambda p: str(p.relative_to(SRC)))
def test_no_ad_hoc_cache(path):
    """Every cache goes through brdfkit._cache: no functools/OrderedDict/weak-dict memo, no
    module-level empty container that is not a declared registry, no `global` state, and
    no `self.*cache* = {}` (a per-object cache is `bounded_cache(None, maxsize=…)`)."""
    rel = str(path.relative_to(SRC))
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) or isinstance(node, ast.Attribute | ast.Name):
            target = node.func if isinstance(node, ast.Call) else node
            name = ast.unparse(target)
            if name in AD_HOC and not (name == "cache" and isinstance(node, ast.Name)
                                       and not _is_decorator(tree, node)):
                pytest.fail(f"{rel}:{node.lineno}: {name} makes an ad-hoc cache; use "
                            "brdfkit._cache.memo or bounded_cache (bounded, registered)")
        if isinstance(node, ast.Global):
            pytest.fail(f"{rel}:{node.lineno}: `global {', '.join(node.names)}`: module "
                        "state set lazily is a cache; use brdfkit._cache.memo(maxsize=1)")
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                if (isinstance(t, ast.Attribute) and "cache" in t.attr.lower()
                        and _empty_container(node.value)):
                    pytest.fail(f"{rel}:{node.lineno}: {ast.unparse(t)} is an unbounded "
                                "per-object cache; use bounded_cache(None, maxsize=…)")
    for node in tree.body:  # module level
        if isinstance(node, ast.Assign | ast.AnnAssign) and _empty_container(node.value):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                name = ast.unparse(t)
                assert (rel, name) in REGISTRIES, (
                    f"{rel}:{node.lineno}: module-level {name} = {ast.unparse(node.value)} "
                    "looks like a cache: make it with brdfkit._cache.bounded_cache (or, if it "
                    "is a registry filled once, add it to REGISTRIES with the reason)")


def _empty_container(value) -> bool:
    if value is None:
        return False
    if isinstance(value, ast.Dict):
        return not value.keys
    if isinstance(value, ast.Set | ast.List):
        return not value.elts
    return (isinstance(value, ast.Call) and ast.unparse(value.func) in ("dict", "set", "list")
            and not value.args)


def _is_decorator(tree, node) -> bool:
    return any(node in f.decorator_list for f in ast.walk(tree)
               if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef))


def _import_all():
    mods = []
    for info in pkgutil.walk_packages([str(SRC)], prefix="brdfkit."):
        try:
            mods.append(importlib.import_module(info.name))
        except ImportError as exc:  # an optional dependency (Mitsuba, FastAPI) is missing
            if "brdfkit" in str(exc):
                raise
    return mods


def test_every_cache_is_registered_under_its_module():
    """Every BoundedCache held by a module (directly, or as a memo's ``cache``) is in the
    registry, under a name that starts with the module that holds it."""
    held = {}
    for mod in _import_all():
        for attr, value in vars(mod).items():
            cache = value if isinstance(value, BoundedCache) else getattr(value, "cache", None)
            if isinstance(cache, BoundedCache) and not attr.startswith("__"):
                held.setdefault(id(cache), (mod.__name__, attr, cache))
    registered = {id(c) for c in CACHES.values()}
    for mod_name, attr, cache in held.values():
        if mod_name == "brdfkit._cache" or cache.name.startswith("test."):
            continue
        assert id(cache) in registered, f"{mod_name}.{attr} is a cache missing from CACHES"
        owner = cache.name.rsplit(".", 1)[0]
        assert owner == mod_name or owner.startswith(mod_name + "."), (
            f"{mod_name}.{attr} is registered as {cache.name!r}: name a cache after its module")
    # and every registered library cache is bounded (no cache without a bound)
    for name, cache in CACHES.items():
        assert 1 <= cache.maxsize <= 4096, f"{name}: maxsize {cache.maxsize}"
    assert _cache.CACHES is CACHES
