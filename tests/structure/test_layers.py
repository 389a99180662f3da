"""Layers of the package: a part of cmsim imports only the parts below it (DESIGN.md, Layout).

Tier: structure (no physics). Every module of ``cmsim`` is parsed with :mod:`ast`; imports at
any depth (inside functions and classes too) count, relative imports are resolved. Each module
belongs to a *unit* (its top-level module or package under ``cmsim``), each unit to a layer:

* a unit may import only units of its own layer or of a lower one, and the graph of units has no
  cycle (so no two units import each other, as the before-stop hook checks);
* no two modules import each other, directly or round a circle, inside a unit too (a name taken
  from a package's ``__init__`` counts as an import of the submodule that defines it);
* an import of a cmsim module inside a function is not allowed (outside ``cmsim/cli/``): it
  hides the layering and is needed only to break an import cycle, which the first rule forbids;
* other function-local imports are allowed only for heavy optional libraries (matplotlib,
  pandas, ...), and anywhere in ``cmsim/cli/`` (start-up time of the command).

Run ``python tests/structure/test_layers.py`` to print every import that breaks a rule.
"""

import ast
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2] / "cmsim"

#: Layers from the bottom up (DESIGN.md, Layout). A unit is the first name under ``cmsim``;
#: ``__init__`` is the package facade ``cmsim/__init__.py``, which re-exports only the rig's
#: values and errors, so it sits with them.
LAYERS = [
    ("ground", {"errors", "_io", "_kernels", "progress"}),
    ("values", {"rig", "run", "frequencies", "__init__"}),
    ("bearings", {"bearings"}),
    ("mesh_stiffness", {"mesh_stiffness"}),
    ("faults", {"faults"}),
    # Not in DESIGN.md's list: losses turn a rig and an operating point into the loads and
    # friction table the dynamics' callers pass to simulate, and read a Run's power balance.
    ("losses", {"losses"}),
    ("dynamics", {"dynamics"}),
    ("sensors", {"sensors"}),
    ("spectra", {"spectra"}),
    # the one measured record: reads files, infers speed and fs on the spectra, builds the
    # model rig; features, diagnostics and discrepancy read records through it
    ("measured", {"measured"}),
    ("features", {"features"}),
    # A calibrated machine: the model's forces through a real machine's path and background.
    ("machine", {"machine"}),
    ("datasets", {"datasets"}),
    # Not in DESIGN.md's list: studies reproduce the paper's results with the whole stack.
    ("studies", {"studies"}),
    ("diagnostics", {"diagnostics"}),
    ("discrepancy", {"discrepancy"}),
    ("cli", {"cli", "__main__"}),
]
LAYER_OF = {unit: i for i, (_, units) in enumerate(LAYERS) for unit in units}

#: Third-party libraries slow to import or needed by one feature only: these may be imported
#: inside the function that needs them.
LAZY_LIBRARIES = {"matplotlib", "pandas", "pyarrow", "dask", "distributed", "tqdm", "skfem",
                  # optional extras (cmsim[uff], cmsim[tdms], cmsim[torch]; h5py for MATLAB
                  # v7.3 files): cmsim imports without them
                  "pyuff", "nptdms", "h5py", "torch"}

#: Units where any function-local import is allowed (start-up time of the command).
LAZY_UNITS = {"cli"}

#: Known exceptions to the layer and local-import rules, "module -> imported module", each
#: with its reason (their edges are also left out of the cycle check). Shrink to empty.
#: (Done: mesh_stiffness/torque_tables.py, which imported dynamics and spectra, moved to
#: cmsim/dynamics/torque_tables.py; cmsim/dynamics lost its function-local imports; the one
#: cage formula moved from bearings.kinematics into cmsim/frequencies.py, below bearings.)
KNOWN_EXCEPTIONS = set()


def module_name(path):
    """Dotted module name of a file under ``cmsim`` (``cmsim.spectra`` for its __init__)."""
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def unit_of(module):
    """First name under ``cmsim`` (``"__init__"`` for the package itself)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imports(module):
    """Yield ``(target module, line, local)`` for every cmsim or third-party import of a module.

    ``from pkg import name`` resolves to the submodule ``pkg.name`` when that is a module.
    ``local`` is True for an import inside a function or class body.
    """
    path = MODULES[module]
    is_package = path.name == "__init__.py"
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))

    def visit(node, local):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.Import):
                for alias in child.names:
                    yield alias.name, child.lineno, local
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    package = module.split(".")
                    package = package[:len(package) - child.level + is_package]
                    base = ".".join(package + ([child.module] if child.module else []))
                else:
                    base = child.module
                for alias in child.names:
                    sub = f"{base}.{alias.name}"
                    if sub not in MODULES:
                        sub = reexported(base).get(alias.name, base)
                    yield sub, child.lineno, local
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef,
                                                ast.ClassDef, ast.Lambda))
            yield from visit(child, inner)

    yield from dict.fromkeys(visit(tree, False))


def reexported(package):
    """{name: defining module} of the names a package's ``__init__`` imports from its
    submodules (empty for a plain module or a third-party package)."""
    path = MODULES.get(package)
    if path is None or path.name != "__init__.py":
        return {}
    found = {}
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom):
            base = (".".join(package.split(".")[:len(package.split(".")) - node.level + 1]
                             + ([node.module] if node.module else []))
                    if node.level else node.module)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found[alias.asname or alias.name] = sub if sub in MODULES else base
    return found


def location(module, line):
    path = MODULES[module]
    return f"{path.relative_to(ROOT.parent) if path.is_relative_to(ROOT) else path}:{line}"


def is_cmsim(target):
    return target == "cmsim" or target.startswith("cmsim.")


def _upward():
    """``(exception key, message)`` for every import of a unit of a higher layer."""
    for module in MODULES:
        mine = LAYER_OF.get(unit_of(module))
        for target, line, _ in imports(module):
            theirs = LAYER_OF.get(unit_of(target)) if is_cmsim(target) else None
            if mine is not None and theirs is not None and theirs > mine:
                yield (f"{module} -> {target}",
                       f"{location(module, line)}: {module} imports {target} "
                       f"(layer {LAYERS[theirs][0]!r} is above {LAYERS[mine][0]!r})")


def upward_imports():
    """Imports of a higher layer not in :data:`KNOWN_EXCEPTIONS`, as ``"file:line: ..."``."""
    return [msg for key, msg in _upward() if key not in KNOWN_EXCEPTIONS]


def unit_graph():
    """Unit -> {imported unit: first 'file:line'} over all imports (known exceptions left out)."""
    graph = {}
    for module in MODULES:
        me = unit_of(module)
        for target, line, _ in imports(module):
            if is_cmsim(target) and f"{module} -> {target}" not in KNOWN_EXCEPTIONS:
                other = unit_of(target)
                if other != me:
                    graph.setdefault(me, {}).setdefault(other, location(module, line))
    return graph


def unit_cycles():
    """Every cycle of the unit graph, as ``"a -> b (file:line) -> a (file:line)"``."""
    graph = unit_graph()
    cycles, seen = [], set()

    def search(path, wheres):
        for nxt, where in sorted(graph.get(path[-1], {}).items()):
            if nxt == path[0] and frozenset(path) not in seen:
                seen.add(frozenset(path))
                steps = [f"{u} ({w})" for u, w in zip(path[1:] + [nxt], wheres + [where])]
                cycles.append(" -> ".join([path[0]] + steps))
            elif nxt not in path and nxt > path[0]:
                search(path + [nxt], wheres + [where])

    for start in sorted(graph):
        search([start], [])
    return cycles


def module_graph():
    """Module -> {imported cmsim module: first 'file:line'} (known exceptions left out)."""
    graph = {}
    for module in MODULES:
        for target, line, _ in imports(module):
            if (is_cmsim(target) and target in MODULES and target != module
                    and f"{module} -> {target}" not in KNOWN_EXCEPTIONS):
                graph.setdefault(module, {}).setdefault(target, location(module, line))
    return graph


def module_cycles():
    """Every circle of imports between modules, as the modules of each strongly connected
    component with the imports that tie them (``"a -> b (file:line)"``)."""
    graph = module_graph()
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def connect(v):                     # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                members = set(component)
                ties = [f"{a} -> {b} ({where})" for a in sorted(members)
                        for b, where in sorted(graph.get(a, {}).items()) if b in members]
                found.append("; ".join(ties))

    for v in sorted(graph):
        if v not in index:
            connect(v)
    return found


def _local():
    """``(exception key, message)`` for every function-local import the rules do not allow."""
    for module in MODULES:
        if unit_of(module) in LAZY_UNITS:
            continue
        for target, line, local in imports(module):
            if not local:
                continue
            if is_cmsim(target):
                yield (f"{module} -> {target}",
                       f"{location(module, line)}: {module} imports {target} inside a "
                       "function; import it at module level")
            elif target.split(".")[0] not in LAZY_LIBRARIES:
                yield (f"{module} -> {target}",
                       f"{location(module, line)}: {target} imported inside a function "
                       f"(only {sorted(LAZY_LIBRARIES)} may be)")


def local_imports():
    """Function-local imports not allowed and not in :data:`KNOWN_EXCEPTIONS`."""
    return [msg for key, msg in _local() if key not in KNOWN_EXCEPTIONS]


def test_every_unit_has_a_layer():
    missing = sorted({unit_of(m) for m in MODULES} - set(LAYER_OF))
    assert not missing, f"add these parts of cmsim to LAYERS in {__file__}: {missing}"


def test_no_import_of_a_higher_layer():
    found = upward_imports()
    assert not found, "imports of a higher layer:\n" + "\n".join(found)


def test_no_two_units_import_each_other():
    found = unit_cycles()
    assert not found, "import cycles between parts of cmsim:\n" + "\n".join(found)


def test_no_two_modules_import_each_other():
    found = module_cycles()
    assert not found, "import circles between modules of cmsim:\n" + "\n".join(found)


def test_no_needless_function_local_imports():
    found = local_imports()
    assert not found, "function-local imports:\n" + "\n".join(found)


def test_known_exceptions_are_still_needed():
    """An exception that no longer excuses a broken rule must be deleted from the list."""
    stale = sorted(KNOWN_EXCEPTIONS - {key for key, _ in [*_upward(), *_local()]})
    assert not stale, f"remove from KNOWN_EXCEPTIONS in {__file__}: {stale}"


@pytest.mark.parametrize("source, expected", [
    ("from cmsim.dynamics import simulate\n", True),
    ("def f():\n    from ..dynamics.model import build_model\n", True),
    ("from cmsim.errors import ParameterError\n", False),
    ("from . import forces\n", False),
])
def test_the_checker_sees_upward_imports(tmp_path, monkeypatch, source, expected):
    """A probe bearings module that imports dynamics (absolute, relative, local) is caught."""
    probe = tmp_path / "probe.py"
    probe.write_text(source)
    monkeypatch.setitem(MODULES, "cmsim.bearings.probe", probe)
    found = [f for f in upward_imports() if str(probe) in f]
    assert bool(found) is expected


def test_the_checker_sees_local_imports_and_cycles(tmp_path, monkeypatch):
    """A probe rig-layer module importing bearings locally gives an upward import, a local
    import and (bearings imports errors, not rig) no cycle; one importing it back gives one."""
    probe = tmp_path / "probe.py"
    probe.write_text("def f():\n    import cmsim.bearings.forces\n    import threading\n")
    monkeypatch.setitem(MODULES, "cmsim.run_probe", probe)
    monkeypatch.setitem(LAYER_OF, "run_probe", LAYER_OF["run"])
    assert len([f for f in local_imports() if str(probe) in f]) == 2
    back = tmp_path / "back.py"
    back.write_text("import cmsim.run_probe\n")
    monkeypatch.setitem(MODULES, "cmsim.bearings.back", back)
    assert any("run_probe" in c and "bearings" in c for c in unit_cycles())


def test_the_checker_sees_circles_inside_a_package(tmp_path, monkeypatch):
    """Three probe modules of one package, a -> b -> c -> a (one through the package's
    ``__init__``), form one circle; without the last import they form none."""
    pkg = tmp_path / "probe"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from cmsim.dynamics.probe.c import thing\n")
    (pkg / "a.py").write_text("from cmsim.dynamics.probe import b\n")
    (pkg / "b.py").write_text("import cmsim.dynamics.probe.c\n")
    (pkg / "c.py").write_text("from cmsim.dynamics.probe.a import x\nthing = 1\n")
    for name in ("__init__", "a", "b", "c"):
        key = "cmsim.dynamics.probe" + ("" if name == "__init__" else f".{name}")
        monkeypatch.setitem(MODULES, key, pkg / f"{name}.py")
    circles = [c for c in module_cycles() if "probe" in c]
    assert len(circles) == 1 and all(f"probe.{m} ->" in circles[0] for m in "abc")
    (pkg / "c.py").write_text("thing = 1\n")
    assert not [c for c in module_cycles() if "probe" in c]
    (pkg / "a.py").write_text("from cmsim.dynamics.probe import thing\n")  # via __init__
    (pkg / "c.py").write_text("import cmsim.dynamics.probe.a\nthing = 1\n")
    assert [c for c in module_cycles() if "probe" in c]


def test_a_comparison_starts_without_the_lazy_libraries():
    """What ``cmsim compare`` imports (every cmsim import of :mod:`cmsim.cli.compare`, its
    functions' too, read from its source) loads none of :data:`LAZY_LIBRARIES`: pandas alone
    was 0.4 s of its 4-s start on a 2-core host, for one peak table a comparison never
    builds. Checked in a fresh interpreter (this one has them)."""
    targets = sorted({t for t, _, _ in imports("cmsim.cli.compare") if is_cmsim(t)})
    assert {t.split(".")[1] for t in targets} >= {"discrepancy", "machine", "measured"}
    code = "".join(f"import {t}\n" for t in ["sys", *targets]) + \
        "print(' '.join(sorted({m.split('.')[0] for m in sys.modules})))\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert "numpy" in out and "cmsim" in out            # the probe ran the imports
    assert not LAZY_LIBRARIES & set(out)


if __name__ == "__main__":
    problems = upward_imports() + unit_cycles() + module_cycles() + local_imports()
    print("\n".join(problems) or "no layering problems")
    sys.exit(bool(problems))
