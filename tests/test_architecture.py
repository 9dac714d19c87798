"""The package tree is the architecture: imports point one way, modules stay small.

Read statically from the source (every ``import`` statement, function-level ones included),
so that a cycle hidden inside a function is found as surely as one at the top of a module.
"""

import ast
from pathlib import Path

import hexdem

PACKAGE = Path(hexdem.__file__).parent
#: Layers in the direction data flows; a module may import only from its own layer or lower ones.
LAYERS = (
    "errors",
    "api_names",
    "common",
    "model",
    "engines",
    "analysis",
    "experiments",
    "theory",
    "waves",
    "disorder",
    "calibration",
    "design",
    "paper",
    "api",
    "cli",
    "__main__",
)
#: Lines as ruff's formatter writes them (one argument a line where a call does not fit in 120 characters).
MAX_LINES = 500


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(path): path for path in PACKAGE.rglob("*.py")}


def imported_modules(path: Path, known) -> set[str]:
    """hexdem modules that ``path`` imports anywhere in its body (``from pkg import mod`` → pkg.mod)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return {name for name in found if name in known}


def import_graph() -> dict[str, set[str]]:
    known = modules()
    return {name: imported_modules(path, known) - {name} for name, path in known.items()}


def layer(name: str) -> int:
    parts = name.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 else len(LAYERS)


def find_cycle(graph) -> list[str] | None:
    """One import cycle of ``graph`` as a list of modules, or None (depth-first search)."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for target in sorted(graph[node]):
            if state.get(target) == "open":
                return stack[stack.index(target) :] + [target]
            if target not in state and (cycle := visit(target)):
                return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycles():
    assert find_cycle(import_graph()) is None


def test_every_package_is_a_known_layer():
    packages = {name.split(".")[1] for name in modules() if name.count(".") >= 1}
    assert packages <= set(LAYERS)


def test_imports_point_down_the_data_flow():
    upward = [
        f"{name} -> {target}"
        for name, targets in import_graph().items()
        for target in targets
        if name != "hexdem" and layer(target) > layer(name)
    ]
    assert upward == []


def test_modules_stay_small():
    large = {name: n for name, path in modules().items() if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert large == {}
