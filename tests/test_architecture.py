"""The package's shape: one-directional imports, no cycles, short modules and functions.

Read from the source with the ast module (nothing is imported).
"""

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "igl_spheremap"

#: Applications: above the core, never imported by it.
APPLICATIONS = ("igl_spheremap.__main__", "igl_spheremap.map_file", "igl_spheremap.cli",
                "igl_spheremap.batch", "igl_spheremap.batch_summary", "igl_spheremap.viz",
                "igl_spheremap.surface_files", "igl_spheremap.io")
MAX_MODULE_LINES = 320
MAX_FUNCTION_LINES = 60  # statements of the body, docstring not counted


def _modules():
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        out[name] = path
    return out


def _imports(name, path):
    """Package modules imported by ``name`` (absolute names; ``from . import x`` resolved)."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.startswith("igl_spheremap"):
                found.add(mod)
                found.update(f"{mod}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("igl_spheremap"))
    return found


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return {m: {d for d in _imports(m, p) if d in modules and d != m}
            for m, p in modules.items()}


def test_there_is_no_import_cycle(graph):
    state = {}

    def visit(m, stack):
        state[m] = "open"
        for d in graph[m]:
            if d == "igl_spheremap" or d.startswith(m + "."):
                continue  # a package importing its own submodules
            if state.get(d) == "open":
                raise AssertionError(" -> ".join(stack + [d]))
            if d not in state:
                visit(d, stack + [d])
        state[m] = "done"

    for m in graph:
        if m not in state:
            visit(m, [m])


def test_the_core_never_imports_the_applications(graph):
    def is_app(m):
        return any(m == a or m.startswith(a + ".") for a in APPLICATIONS)

    bad = [(m, d) for m, deps in graph.items() if not is_app(m) and m != "igl_spheremap"
           for d in deps if is_app(d)]
    assert not bad


def test_modules_and_functions_are_short():
    long_modules, long_functions = [], []
    for name, path in _modules().items():
        src = path.read_text()
        if len(src.splitlines()) > MAX_MODULE_LINES:
            long_modules.append((name, len(src.splitlines())))
        for node in ast.walk(ast.parse(src)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                body = node.body
                doc = isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                start = body[1].lineno if doc and len(body) > 1 else body[0].lineno
                if node.end_lineno - start + 1 > MAX_FUNCTION_LINES:
                    long_functions.append((name, node.name, node.end_lineno - start + 1))
    assert not long_modules
    assert not long_functions
