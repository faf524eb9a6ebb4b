"""The fitting package's structure (issue 18): stages and losses as objects.

- no function in ``brdfkit/fitting/`` is over 80 lines;
- no string test of a procedure or a loss (``procedure == "nielsen"``,
  ``loss in ("l1", "l2")``) anywhere in ``src/``: they are objects in their registries
  (``brdfkit.fitting.procedure.PROCEDURES``, ``brdfkit.fitting.losses.REGISTRY``);
- the registries' dispatchers name the valid choices; the CLI's choices are theirs.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "brdfkit"
MAX_FUNCTION_LINES = 80
WORDS = ("procedure", "loss")


def _sources(root):
    return sorted(p for p in root.rglob("*.py"))


@pytest.mark.parametrize("path", _sources(SRC / "fitting"),
                         ids=lambda p: str(p.relative_to(SRC)))
def test_no_fitting_function_over_80_lines(path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            n = node.end_lineno - node.lineno + 1
            assert n <= MAX_FUNCTION_LINES, f"{path}:{node.lineno}: {node.name} has {n} lines"


def _names_a_loss_or_procedure(node) -> bool:
    """`loss`, `self.procedure`, `job.loss`, `row["loss"]`, `row.get("procedure")`, …"""
    if isinstance(node, ast.Name):
        name = node.id
    elif isinstance(node, ast.Attribute):
        name = node.attr
    elif isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant):
        name = str(node.slice.value)
    elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
          and node.func.attr == "get" and node.args and isinstance(node.args[0], ast.Constant)):
        name = str(node.args[0].value)
    else:
        return False
    return any(part in WORDS for part in name.split("_"))


def _is_string_or_strings(node) -> bool:
    if isinstance(node, ast.Constant):
        return isinstance(node.value, str)
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return bool(node.elts) and all(isinstance(e, ast.Constant) and isinstance(e.value, str)
                                       for e in node.elts)
    return False


def _string_tests(tree):
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        sides = [node.left, *node.comparators]
        for a, b in zip(sides, sides[1:], strict=False):
            if ((_names_a_loss_or_procedure(a) and _is_string_or_strings(b))
                    or (_names_a_loss_or_procedure(b) and _is_string_or_strings(a))):
                yield node


@pytest.mark.parametrize("path", _sources(SRC), ids=lambda p: str(p.relative_to(SRC)))
def test_no_string_tests_of_losses_or_procedures(path):
    found = [n.lineno for n in _string_tests(ast.parse(path.read_text()))]
    assert not found, (f"{path}: lines {found} test a loss or procedure by name; use its "
                       "object's attributes (brdfkit.fitting.losses, .procedure)")


def test_the_checker_finds_string_tests():
    # the checker itself, on the forms it must catch and one it must not
    caught = ['procedure == "nielsen"', 'loss in ("l1", "l2")', 'self.loss != "ngan"',
              'loss == "l2" if x else y', 'row["procedure"] == "direct"',
              'r.get("loss") not in ("log",)', '"perceptual" == loss_name']
    for src in caught:
        assert list(_string_tests(ast.parse(src))), src
    assert not list(_string_tests(ast.parse('losses == other or "l1" in names')))


def test_dispatchers_name_the_choices():
    from brdfkit.errors import ParameterError
    from brdfkit.fitting.losses import LOSSES, REGISTRY, loss
    from brdfkit.fitting.procedure import PROCEDURE_NAMES, PROCEDURES, get_procedure

    assert LOSSES == ("l1", "l2", "ngan", "log", "perceptual")
    assert PROCEDURE_NAMES == ("auto", "staged", "nielsen", "direct")
    assert get_procedure("auto") is PROCEDURES["staged"]
    assert loss("ngan") is REGISTRY["ngan"]
    with pytest.raises(ParameterError, match="l1, l2, ngan, log, perceptual; got 'l3'"):
        loss("l3")
    with pytest.raises(ParameterError, match="auto, staged, nielsen, direct; got 'fast'"):
        get_procedure("fast")


def test_cli_choices_come_from_the_registries():
    from brdfkit.cli.fit_commands import fit_cmd
    from brdfkit.fitting.losses import LOSSES
    from brdfkit.fitting.procedure import PROCEDURE_NAMES

    opts = {p.name: p for p in fit_cmd.params}
    assert tuple(opts["loss"].type.choices) == LOSSES
    assert tuple(opts["procedure"].type.choices) == PROCEDURE_NAMES


def test_loss_objects_declare_what_the_stages_read():
    # which losses make variable projection exact, need albedos, solve by IRLS, mask
    # samples: the properties the procedure used to test by name (docs/fitting.md)
    from brdfkit.fitting.losses import REGISTRY
    from brdfkit.fitting.samples import merl_samples

    exact = {n for n, L in REGISTRY.items() if L.exact_projection}
    assert exact == {"l1", "l2", "ngan"}
    assert {n for n, L in REGISTRY.items() if L.needs_albedo} == {"perceptual"}
    assert {n for n, L in REGISTRY.items() if L.irls} == {"l1"}
    s = merl_samples()
    masked = {n: L.sample_mask(s) for n, L in REGISTRY.items()}
    assert all(v is None for n, v in masked.items() if n != "ngan")
    # Ngan's cut-off: both directions within 80° of the normal (cos 80° = 0.17365)
    import math

    c = math.cos(math.radians(80.0))
    k = masked["ngan"]
    assert k.dtype == bool and 0 < k.sum() < k.size
    assert ((s.wi[k, 2] >= c) & (s.wo[k, 2] >= c)).all()
    assert not ((s.wi[~k, 2] >= c) & (s.wo[~k, 2] >= c)).any()
