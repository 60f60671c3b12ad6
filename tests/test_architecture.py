"""The tree keeps the shape a newcomer can live in: small classes, modules and
functions; no private attribute of another module's class touched; no import
cycle between the project's modules, imports inside functions included.

Counted on the source (AST), so the rules hold for code that no test runs.
Numba kernels (functions decorated with ``njit``, and modules made mostly of
them) are exempt from the size limits: a kernel is one loop a reader follows
top to bottom, and splitting it costs speed.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGES = ("foldcore", "elements")
MAX_CLASS, MAX_MODULE, MAX_FUNCTION = 400, 600, 80


def modules() -> dict[str, Path]:
    """Dotted name → path of every module of the project's packages."""
    out = {}
    for path in sorted(SRC.rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[0] not in PACKAGES:
            continue
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = modules()
TREES = {name: ast.parse(path.read_text(), str(path)) for name, path in MODULES.items()}


def is_kernel(node) -> bool:
    """Whether a function is a numba kernel (decorated with njit / numba.njit)."""
    for deco in getattr(node, "decorator_list", []):
        target = deco.func if isinstance(deco, ast.Call) else deco
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit", "vectorize", "guvectorize"):
            return True
    return False


def kernel_module(tree) -> bool:
    functions = [n for n in tree.body if isinstance(n, ast.FunctionDef)]
    return bool(functions) and sum(map(is_kernel, functions)) >= len(functions) / 2


def span(node) -> int:
    return node.end_lineno - node.lineno + 1


def test_no_class_function_or_module_over_its_size():
    too_long = []
    for name, tree in TREES.items():
        kernels = kernel_module(tree)
        lines = len(MODULES[name].read_text().splitlines())
        if lines > MAX_MODULE and not kernels:
            too_long.append(f"module {name}: {lines} lines")
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and span(node) > MAX_CLASS:
                too_long.append(f"class {name}.{node.name}: {span(node)} lines")
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) \
                    and span(node) > MAX_FUNCTION and not is_kernel(node):
                too_long.append(f"function {name}.{node.name}: {span(node)} lines")
    assert not too_long, "\n".join(too_long)


def private_names(tree) -> set[str]:
    """Private (single-underscore) names a module defines: its functions, classes,
    module-level names, class attributes and ``self._x`` / ``cls._x`` attributes."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
    return {n for n in names if n.startswith("_") and not n.startswith("__")}


def test_no_private_attribute_of_another_modules_class_is_touched():
    """``obj._x`` is allowed on ``self``/``cls`` or where ``_x`` is this module's own
    name; a private name of the project defined only in other modules is not, and
    neither is importing one."""
    own = {name: private_names(tree) for name, tree in TREES.items()}
    everywhere = set().union(*own.values())
    found = []
    for name, tree in TREES.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr in everywhere \
                    and node.attr not in own[name]:
                base = node.value
                if not (isinstance(base, ast.Name) and base.id in ("self", "cls")):
                    found.append(f"{name}:{node.lineno}: .{node.attr}")
            if isinstance(node, ast.ImportFrom) and node.level + bool(node.module):
                target = resolve(name, node)
                if target in MODULES:
                    found += [f"{name}:{node.lineno}: imports {a.name} from {target}"
                              for a in node.names
                              if a.name.startswith("_") and not a.name.startswith("__")]
    assert not found, "\n".join(found)


def resolve(module: str, node: ast.ImportFrom) -> str:
    """The dotted module an ``import from`` names (relative levels resolved)."""
    if not node.level:
        return node.module or ""
    is_package = MODULES[module].name == "__init__.py"
    base = module.split(".")
    base = base[:len(base) - node.level + (1 if is_package else 0)]
    return ".".join(base + ([node.module] if node.module else []))


def imports(module: str, tree) -> set[str]:
    """The project modules ``module`` imports anywhere in its body (functions too).
    A registry's import of a type by name (``importlib``) is not an edge: the type's
    module imports the registry's base class, by design."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            target = resolve(module, node)
            submodules = {f"{target}.{a.name}" for a in node.names} & set(MODULES)
            out |= submodules  # `from . import sibling` imports the sibling only
            if len(submodules) < len(node.names):  # a name defined by the package itself
                out.add(target)
    return {m for m in out if m in MODULES and m != module}


def test_the_import_graph_has_no_cycle():
    """Lazy imports included; a package importing its own submodules is not a cycle,
    a submodule importing its package back (or through others) is."""
    graph = {name: imports(name, tree) for name, tree in TREES.items()}
    cycles, state = [], {}

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(" → ".join(path[path.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
    assert not cycles, "\n".join(cycles)


#: The layers of the run, top to bottom: a module never imports (lazily included) one
#: of a layer above its own. The data side (pattern, thick mesh, readers) is below all.
LAYERS = [
    ("foldcore.cli", "foldcore.demo", "foldcore.warmup", "foldcore.__main__",
     "foldcore.interrupts", "foldcore.result_commands"),
    ("foldcore.job", "foldcore.scenes", "foldcore.sheet_job"),
    ("foldcore.animate", "foldcore.view", "foldcore.outputs", "foldcore.render",
     "foldcore.fabrication", "foldcore.destinations", "foldcore.result_file",
     "foldcore.surface", "foldcore.sheet_outputs", "foldcore.sheet_render"),
    ("foldcore.simulation", "foldcore.result"),
    ("foldcore.strategies",),
    ("foldcore.convergence", "foldcore.probe", "foldcore.certificate"),
    ("foldcore.model", "foldcore.sheet"),
    ("foldcore.system", "foldcore.linsolve", "foldcore.threads"),
    ("foldcore.thickening", "foldcore.io", "foldcore.pattern", "foldcore.mesh",
     "foldcore.measure", "foldcore.strain", "foldcore.patterns", "foldcore.planar",
     "foldcore.kinematics", "foldcore.limits", "foldcore.hinges", "foldcore.actuation",
     "foldcore.errors", "foldcore.files", "foldcore.triangulation", "foldcore.cuts",
     "elements"),
]


def layer(module: str) -> int | None:
    for i, prefixes in enumerate(LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return i
    return None


def test_no_module_imports_a_layer_above_its_own():
    """E.g. a strategy never reaches up to the run driver, the model never to a
    strategy, a reader never to the model (import-linter's layers contract)."""
    upward = []
    for name, tree in TREES.items():
        own = layer(name)
        for target in imports(name, tree):
            above = layer(target)
            if own is not None and above is not None and above < own:
                upward.append(f"{name} imports {target}")
    assert not upward, "\n".join(upward)


@pytest.mark.parametrize("name", ["foldcore.strategies", "foldcore.model", "elements"])
def test_solver_layers_never_import_rendering(name):
    """Rendering stays optional: the model, strategies and element kernels never
    import pyvista (or the modules that do)."""
    prefix = name + "."
    for module, tree in TREES.items():
        if module != name and not module.startswith(prefix):
            continue
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            assert not any(n.split(".")[0] == "pyvista" or n.endswith("render")
                           for n in names), f"{module} imports rendering"
