"""At most four hand-written loops over direction pairs remain in src/ (issue 18).

A loop over direction pairs is a ``for`` loop that reads both an incident and an outgoing
direction array at a variable index (``wi[j, …]`` and ``wo[j, …]``, or the flat views
``a[3 * j …]``/``b[3 * j …]`` of the vectorised loop). Every other such loop is
generated from these by :mod:`brdfkit.models._drivers` (``LOOPS``, ``composed``): the scan
below reads the source, so a new hand-written copy fails here. Reference: the count of the
issue's criterion and the loops it names (the three copies in ``data/surrogates.py`` gone).
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "brdfkit"
INCOMING, OUTGOING = {"wi", "a"}, {"wo", "b"}

#: The hand-written pair loops: loop → its functions (file, function) and why it is one.
ALLOWED = {
    "checked (and plain)": ({("models/_drivers.py", "eval_pairs_checked")},
                            "LOOPS['checked'], LOOPS['plain']"),
    "vector": ({("models/_drivers.py", "_vector_chunk"), ("models/_drivers.py", "_vector_loop")},
               "LOOPS['vector']: the chunk LLVM vectorises, the parallel loop over chunks"),
    "blocked": ({("models/_drivers.py", "_blocked_loop")}, "LOOPS['blocked'] (table lookups)"),
    "nbrdf": ({("data/surrogates.py", "nbrdf_driver")},
              "NBRDF's net, all channels from one evaluation, a matrix product per block"),
}
ALLOWED_FUNCTIONS = set().union(*(functions for functions, _ in ALLOWED.values()))


def _reads(node: ast.AST, names: set[str]) -> bool:
    """Whether *node* reads one of the arrays *names* at an index holding a variable:
    ``a[i]``, or ``load_input(a, i)`` (brdfkit._kern's tagged read, the vector loop's)."""
    for sub in ast.walk(node):
        if (isinstance(sub, ast.Subscript) and isinstance(sub.ctx, ast.Load)
                and isinstance(sub.value, ast.Name) and sub.value.id in names
                and any(isinstance(n, ast.Name) for n in ast.walk(sub.slice))):
            return True
        if (isinstance(sub, ast.Call) and isinstance(sub.func, ast.Name)
                and sub.func.id == "load_input" and len(sub.args) == 2
                and isinstance(sub.args[0], ast.Name) and sub.args[0].id in names
                and any(isinstance(n, ast.Name) for n in ast.walk(sub.args[1]))):
            return True
    return False


def _is_pair_loop(node: ast.AST) -> bool:
    return isinstance(node, ast.For) and _reads(node, INCOMING) and _reads(node, OUTGOING)


def pair_loops() -> set[tuple[str, str]]:
    """(file, function) of every function holding a loop over direction pairs."""
    found = set()
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for fn in ast.walk(tree):
            if not isinstance(fn, ast.FunctionDef):
                continue
            if any(_is_pair_loop(node) for node in ast.walk(fn)):
                found.add((path.relative_to(SRC).as_posix(), fn.name))
    return found


def test_at_most_four_hand_written_pair_loops():
    found = pair_loops()
    assert len(ALLOWED) <= 4
    extra = sorted(found - ALLOWED_FUNCTIONS)
    assert not extra, f"hand-written pair loops (generate them: models/_drivers): {extra}"
    assert found == ALLOWED_FUNCTIONS  # each allowed loop still exists (the scan sees it)


def test_the_scan_finds_a_hand_written_loop():
    # a copy of the surrogates' former loop is found; a loop over wo alone is not
    src = ("def drv(wi, wo, P, out):\n"
           "    for j in numba.prange(wi.shape[0]):\n"
           "        out[j, 0] = k(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1],\n"
           "                      wo[j, 2], P[0])\n"
           "def rows(wo, out):\n"
           "    for j in range(wo.shape[0]):\n"
           "        out[j] = wo[j, 2]\n"
           "def pixels(wi, wo):\n"
           "    for k in range(4):\n"
           "        wi[k, 0] = wo[k, 0] = 0.0\n")  # writes only: generates pairs
    tree = ast.parse(src)
    hits = [fn.name for fn in tree.body if any(_is_pair_loop(n) for n in ast.walk(fn))]
    assert hits == ["drv"]
