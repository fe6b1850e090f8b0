"""The package's layers, read from its sources: no import cycle, no import from a higher layer
into a lower one, and the registry of backends matching what the pipeline and README say."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

import impactqp as iq
from impactqp.laws.catalogue import LAWS, backend_table

PACKAGE = Path(iq.__file__).parent
ROOT = PACKAGE.parent

# rank of each top-level part of impactqp: a module may import only from its own rank or lower
LAYERS = {
    "errors": 0, "base": 0, "kernels": 0,
    "qp": 1,
    "model": 2,
    "tables": 3,
    "laws": 4, "derivatives": 4,
    "verification": 5, "simulation": 5,
    "io": 6, "figures": 6,
    "cli": 7, "interop": 7,
    "__init__": 8, "__main__": 8, "precompile": 7,
    # the public submodules re-export from every layer
    "problems": 8, "results": 8, "friction": 8, "chains": 8, "collection": 8,
}
# edges that the ranks allow but the design forbids
FORBIDDEN = [("qp.backends", "model"), ("qp", "laws"), ("model", "laws"), ("base", "kernels"),
             ("errors", "kernels")]


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__" and len(parts) > 1:
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path) -> set[str]:
    """Every impactqp module imported by ``path`` (also inside functions)."""
    name = module_name(path)
    is_pkg = path.name == "__init__.py"
    package = name.split(".") if is_pkg else name.split(".")[:-1]
    if name == "__init__":
        package = []
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.startswith("impactqp"):
                target = node.module.removeprefix("impactqp").lstrip(".")
            else:
                continue
            for alias in node.names:  # "from . import backends" names a module
                candidate = f"{target}.{alias.name}" if target else alias.name
                if (PACKAGE / candidate.replace(".", "/")).with_suffix(".py").exists() or \
                        (PACKAGE / candidate.replace(".", "/") / "__init__.py").exists():
                    out.add(candidate)
                else:
                    out.add(target or "__init__")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("impactqp."):
                    out.add(alias.name.removeprefix("impactqp."))
    out.discard(name)
    return out


def graph() -> dict[str, set[str]]:
    return {module_name(p): imports_of(p) for p in PACKAGE.rglob("*.py")}


def layer(module: str) -> int:
    return LAYERS[module.split(".")[0]]


def test_every_module_has_a_layer() -> None:
    assert all(m.split(".")[0] in LAYERS for m in graph())


def test_no_import_from_a_higher_layer() -> None:
    bad = [(m, t) for m, targets in graph().items() for t in targets if layer(t) > layer(m)]
    assert bad == []


def test_forbidden_edges() -> None:
    bad = [(m, t) for m, targets in graph().items() for t in targets
           for low, high in FORBIDDEN if m.startswith(low) and t.startswith(high)]
    assert bad == []


def test_no_import_cycle() -> None:
    g = graph()
    state: dict[str, int] = {}
    cycle: list[str] = []

    def visit(node: str, stack: list[str]) -> bool:
        state[node] = 1
        for nxt in sorted(g.get(node, ())):
            if state.get(nxt) == 1:
                cycle.extend(stack[stack.index(nxt):] + [node, nxt] if nxt in stack else
                             [node, nxt])
                return True
            if state.get(nxt) is None and visit(nxt, stack + [node]):
                return True
        state[node] = 2
        return False

    for node in sorted(g):
        if state.get(node) is None and visit(node, []):
            break
    assert cycle == []


def test_graph_sees_real_edges() -> None:
    # the checks above would pass vacuously if the parser missed imports
    g = graph()
    assert "laws.pipeline" in g["laws.functions"]
    assert "qp.certified" in g["laws.pipeline"]
    assert "model.structure" in g["model.problem"]


def test_modules_stay_small() -> None:
    sizes = {module_name(p): len(p.read_text(encoding="utf-8").splitlines())
             for p in PACKAGE.rglob("*.py")}
    assert {m: n for m, n in sizes.items() if n > 360} == {}


MAX_PARAMETERS = 15
"""Most parameters of a function in impactqp/kernels: more travel grouped in named tuples
(the system's contacts, the force, the scheme, the event buffers), not one by one."""

MAX_LINES = 100
"""Most lines of a kernel function."""

def kernel_functions() -> dict[str, tuple[int, int]]:
    """(parameters, lines) of every function in impactqp/kernels, by ``module.name``."""
    out = {}
    for path in sorted((PACKAGE / "kernels").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef):
                a = node.args
                count = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + \
                    (a.vararg is not None) + (a.kwarg is not None)
                out[f"{path.stem}.{node.name}"] = (count, node.end_lineno - node.lineno + 1)
    return out


def test_kernels_take_grouped_arguments() -> None:
    functions = kernel_functions()
    assert functions["moreau_jean.run"][0] <= MAX_PARAMETERS  # the check sees the loops
    assert functions["lzb._piece"][0] <= MAX_PARAMETERS  # and the LZB stepper's
    wide = {name: n for name, (n, _) in functions.items() if n > MAX_PARAMETERS}
    assert wide == {}
    long = {name: lines for name, (_, lines) in functions.items() if lines > MAX_LINES}
    assert set(long) <= {"lzb._piece"}


def test_import_with_required_dependencies_only() -> None:
    # optional extras (matplotlib, piqp, daqp, ...) must not be needed to import impactqp
    code = ("import sys\n"
            "for name in ('matplotlib', 'piqp', 'daqp', 'ecos', 'quadprog', 'dask'):\n"
            "    sys.modules[name] = None\n"
            "import impactqp as iq\n"
            "print(iq.moreau(iq.newtons_cradle(), 1.0).u_plus)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr


# --------------------------------------------------------------------------- registry
BACKENDS = [b["name"] for b in iq.available_backends()]
SUB = {"qpsolvers": "qpsolvers:daqp", "cvxpy": "cvxpy"}


@pytest.mark.parametrize("form", ["auto", "velocity", "impulse"])
@pytest.mark.parametrize("name", BACKENDS)
@pytest.mark.parametrize("problem", ["cradle", "random", "sparse"])
def test_every_backend_and_form_works_or_says_why(name: str, form: str, problem: str) -> None:
    p = {"cradle": iq.newtons_cradle(3),
         "random": iq.random_impact(6, 4, seed=1),
         "sparse": iq.chain([1.0, 2.0, 3.0, 4.0], [1.0, 0.0, -1.0, 0.0], sparse=True)}[problem]
    reference = iq.moreau(p, 1.0, backend="exact").u_plus
    backend = SUB.get(name, name)
    try:
        r = iq.solve(p, iq.Moreau(1.0), backend=backend, form=form)
    except iq.BackendUnsuitableError as exc:
        assert str(exc)  # says why
        entry = next(b for b in iq.available_backends() if b["name"] == name)
        assert form == "auto" or form not in entry["forms"] or "sparse" in problem or \
            "chain" in str(exc) or "contacts" in str(exc)
        return
    assert r.ok and r.certificate.ok
    assert r.form in ("velocity", "impulse") and (form == "auto" or r.form == form)
    assert abs(r.u_plus - reference).max() <= 1e-9


def test_named_fast_paths_serve_other_laws_and_lcps() -> None:
    p = iq.newtons_cradle(3)
    assert iq.moreau(p, 1.0, backend="kernel", form="impulse").backend == "kernel"
    assert iq.solve(p, iq.Newton([1.0, 0.5]), backend="kernel").backend == "kernel"
    assert iq.solve_lcp([[2, -1], [-1, 2]], [-1, 0], backend="kernel").backend == "kernel"
    with pytest.raises(iq.BackendUnsuitableError, match="velocity form of 1-D chains"):
        iq.moreau(iq.random_impact(4, 3, seed=0), backend="isotonic")
    with pytest.raises(iq.BackendUnsuitableError, match="closed form"):
        iq.solve(p, iq.SectorLaw(), backend="clarabel")
    with pytest.raises(iq.InputError, match="no velocity form"):
        iq.solve(p, iq.Newton(0.5), form="velocity")


def test_readme_table_is_the_registry() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert backend_table() in readme
    rows = re.findall(r"^\| `\"([a-z-]+)\"` \|", readme, flags=re.M)
    assert rows == ["auto"] + BACKENDS
    assert [law.name for law in LAWS] == ["moreau", "newton", "fremond", "sector", "reflection",
                                          "lzb"]


def built_in_law_names() -> set[str]:
    """Names of the package's impact law classes (every subclass of ImpactLaw it defines)."""
    found, todo = set(), [iq.ImpactLaw]
    while todo:
        cls = todo.pop()
        for sub in cls.__subclasses__():
            if sub.__module__.startswith("impactqp."):
                found.add(sub.__name__)
            todo.append(sub)
    return found


def law_class_checks(source: str, names: set[str]) -> list[int]:
    """Lines of ``source`` that recognise a law by its class: isinstance/issubclass against
    a law class, ``type(x)`` compared with one (``is``, ``==``) or looked up in anything
    (``in``), or a tuple of law classes."""

    def mentions(node: ast.AST) -> bool:
        return any(isinstance(n, ast.Name) and n.id in names
                   or isinstance(n, ast.Attribute) and n.attr in names for n in ast.walk(node))

    def is_type_of(node: ast.AST) -> bool:
        return (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id == "type") or (isinstance(node, ast.Attribute)
                                                 and node.attr == "__class__")

    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id in ("isinstance", "issubclass") and len(node.args) == 2 \
                and mentions(node.args[1]):
            lines.append(node.lineno)
        elif isinstance(node, ast.Compare) and is_type_of(node.left) and (
                any(isinstance(op, (ast.In, ast.NotIn)) for op in node.ops)
                or any(mentions(c) for c in node.comparators)):
            lines.append(node.lineno)
        elif isinstance(node, ast.Tuple) and sum(isinstance(e, ast.Name) and e.id in names
                                                 for e in node.elts) >= 2:
            lines.append(node.lineno)
    return lines


def test_the_scan_for_law_classes_sees_them() -> None:
    names = built_in_law_names()
    assert {"Moreau", "Newton", "Fremond", "SectorLaw", "ReflectionLaw", "LZB",
            "Coulomb", "MoreauJeanStep"} <= names
    bad = ("if isinstance(law, Coulomb): pass\nok = type(law) is Moreau\n"
           "fast = type(law) in FAST\nFAST = (Moreau, Newton)\nx = isinstance(law, ImpactLaw)\n"
           "y = type(value) is not float\nz = law.family is not None\n")
    assert law_class_checks(bad, names) == [1, 2, 3, 4]


def test_no_law_is_recognised_by_its_class() -> None:
    # what a law can do is declared on it (family, frictional, restitution_per_contact,
    # compliant) and read by every fast path: outside the laws, no module asks for a class,
    # and neither do the laws' own fast paths and planner
    names = built_in_law_names()
    fast_paths = {"laws/small.py", "laws/batch.py", "laws/chain_rows.py", "laws/parallel.py",
                  "laws/planner.py", "laws/pipeline.py"}
    found = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("laws/") and rel not in fast_paths:
            continue
        lines = law_class_checks(path.read_text(encoding="utf-8"), names)
        if lines:
            found[rel] = lines
    assert found == {}
