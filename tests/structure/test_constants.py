"""Each unit constant is written once (STYLE.md, "one of each"): in cmsim/measured/schema.py.

Tier: structure (no physics). Every module of ``cmsim`` is parsed with :mod:`ast`; a number
literal equal to standard gravity, the pound-force or the inch anywhere but in
``cmsim/measured/schema.py`` is a second copy (they drift: two record classes once differed
in the pound-force).
"""

import ast
import pathlib

import pytest

from cmsim.measured.schema import INCH_M, LBF_N, STANDARD_GRAVITY_M_S2

ROOT = pathlib.Path(__file__).resolve().parents[2] / "cmsim"
HOME = ROOT / "measured" / "schema.py"


@pytest.mark.parametrize("name, value", [("STANDARD_GRAVITY_M_S2", STANDARD_GRAVITY_M_S2),
                                         ("LBF_N", LBF_N), ("INCH_M", INCH_M)])
def test_unit_constants_are_defined_once(name, value):
    copies = [f"{path.relative_to(ROOT.parent)}:{node.lineno}"
              for path in sorted(ROOT.rglob("*.py")) if path != HOME
              for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
              if isinstance(node, ast.Constant) and type(node.value) is float
              and abs(node.value - value) <= 1e-12 * value]
    assert not copies, f"{name} written again (import it from cmsim.measured.schema): {copies}"
