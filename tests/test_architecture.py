"""The package's layers hold (``docs/architecture.md``): read from the source, not by importing it.

- No import cycle among the package's modules, and no import of a package module inside a function
  (the way a cycle used to be hidden).
- The layers: the physics (everything below the renderer) never imports the renderer or the
  applications; the renderer never imports the applications; the numpy reference imports nothing
  of the torch code; nothing imports ``pipelines`` or ``examples``.
- No private name reached across modules: neither ``from .x import _name`` nor ``obj._attr`` where
  ``_attr`` is defined in another module (exceptions are listed below, each with its reason).
- No module longer than ~600 lines.

Each check was planted once (an import of the renderer inside ``foam.py``'s function, a
``from .optics import _x``, ``geom._dx``) and failed.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "roughsea_torch"
ROOT = "roughsea_torch"

# modules above the renderer: they use images (clips, augmentations, sensors, datasets, brute force)
APPLICATIONS = ("motion", "sensitivity", "sensor", "_sensor", "augmentation", "_augmentation", "sampling", "parameter_render",
                "dataset", "raytrace")

# (module, name): reason. Private names that one module may take from another.
PRIVATE_ALLOWED: dict[tuple[str, str], str] = {
    ("*", "sys._getframe"): "the standard library's frame access, to point a warning at the user's line",
    ("*", "os._exit"): "the standard library's immediate exit, to simulate a crash in the dataset writer's test hook",
}

MAX_LINES = 620


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()
TREES = {name: ast.parse(path.read_text(), str(path)) for name, path in MODULES.items()}


def _target(module: str, node: ast.ImportFrom) -> str:
    """The absolute module an ``ImportFrom`` names (``from . import x`` names the package)."""
    if not node.level:
        return node.module or ""
    pkg = module if MODULES[module].name == "__init__.py" else module.rsplit(".", 1)[0]
    base = pkg.split(".")[: len(pkg.split(".")) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str, tree: ast.AST) -> list[tuple[str, ast.AST]]:
    """(imported package module, node) for every import of a package module in ``tree``: a name
    imported from a package is the submodule when one exists by that name."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            tgt = _target(module, node)
            if tgt == ROOT or tgt.startswith(ROOT + "."):
                for alias in node.names:
                    sub = f"{tgt}.{alias.name}"
                    out.append((sub if sub in MODULES else tgt, node))
        elif isinstance(node, ast.Import):
            out += [(a.name, node) for a in node.names if a.name == ROOT or a.name.startswith(ROOT + ".")]
    return out


def _top_level_graph() -> dict[str, set[str]]:
    graph = {m: set() for m in MODULES}
    for m, tree in TREES.items():
        for tgt, _ in _imports(m, tree):
            if tgt in MODULES and tgt != m:
                graph[m].add(tgt)
    return graph


def _layer(module: str) -> str:
    parts = module.split(".")
    if module == ROOT:
        return "package"
    if parts[1] == "reference":
        return "reference"
    if parts[1] == "renderer":
        return "renderer"
    if parts[1].startswith(APPLICATIONS):
        return "applications"
    return "physics"


ALLOWED = {"physics": {"physics"}, "renderer": {"physics", "renderer"},
           "applications": {"physics", "renderer", "applications"}, "reference": {"reference"},
           "package": {"physics", "renderer", "applications", "reference", "package"}}


def test_no_import_cycle():
    graph = _top_level_graph()
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(n):] + [n]))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_no_package_import_inside_a_function():
    found = []
    for m, tree in TREES.items():
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for node in fn.body:
                    for sub in ast.walk(node):
                        if isinstance(sub, (ast.Import, ast.ImportFrom)) and _imports(m, ast.Module([sub], [])):
                            found.append(f"{m}:{sub.lineno} in {fn.name}()")
    assert not found, "imports of package modules inside functions (import at the top; a cycle is a layering bug): " + ", ".join(sorted(set(found)))


def test_layers():
    bad = []
    for m, deps in _top_level_graph().items():
        for d in deps:
            if _layer(d) not in ALLOWED[_layer(m)]:
                bad.append(f"{m} ({_layer(m)}) imports {d} ({_layer(d)})")
    assert not bad, "\n".join(sorted(bad))


def test_package_never_imports_pipelines_or_examples():
    bad = [f"{m}:{n.lineno}" for m, tree in TREES.items() for n in ast.walk(tree)
           if isinstance(n, (ast.Import, ast.ImportFrom))
           and any(a.startswith(("pipelines", "examples")) for a in
                   ([x.name for x in n.names] if isinstance(n, ast.Import) else [n.module or ""]))]
    assert not bad


def _defined_private_names(tree: ast.AST) -> set[str]:
    """Private names a module defines: functions, classes, assigned names and attributes (self._x = ...)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return {n for n in names if n.startswith("_")}


def test_no_private_name_reached_across_modules():
    bad = []
    for m, tree in TREES.items():
        own = _defined_private_names(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                tgt = _target(m, node)
                if tgt.startswith(ROOT) and tgt != m:
                    bad += [f"{m}:{node.lineno} from {tgt} import {a.name}" for a in node.names
                            if a.name.startswith("_") and not a.name.startswith("__")
                            and (m, a.name) not in PRIVATE_ALLOWED]
            elif isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
                owner = node.value
                if isinstance(owner, ast.Name) and owner.id in ("self", "cls"):
                    continue
                if node.attr in own:  # the module's own private attribute, on another instance of its class
                    continue
                where = f"{ast.unparse(owner)}.{node.attr}"
                if ("*", where) in PRIVATE_ALLOWED or (m, where) in PRIVATE_ALLOWED:
                    continue
                bad.append(f"{m}:{node.lineno} {where}")
    assert not bad, "private names reached across modules:\n" + "\n".join(bad)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_module_length(module):
    lines = MODULES[module].read_text().count("\n")
    assert lines <= MAX_LINES, f"{MODULES[module]}: {lines} lines; split it by topic"
