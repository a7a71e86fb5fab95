"""No import cycle between the subpackages of floodsph.

The graph is built from the source with ``ast``: every ``import`` statement counts, at module
level or inside a function, so a cycle cannot be hidden by a deferred import. A node is a
subpackage (``floodsph.sph``, ``floodsph.walls``, ...); the top-level modules
(``floodsph.constants``, ``floodsph.errors``, ...) are nodes of their own.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "floodsph"


def _node(module: str) -> str | None:
    """The graph node of a dotted module name, or None outside floodsph."""
    parts = module.split(".")
    if parts[0] != "floodsph":
        return None
    return ".".join(parts[:2]) if len(parts) > 1 else "floodsph"


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imported_modules(path: Path) -> set[str]:
    """Every floodsph module a file imports, anywhere in the file."""
    name = _module_name(path)
    is_package = path.name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            found.add(target)
            # `from floodsph import sph` imports the subpackage floodsph.sph
            for alias in node.names:
                found.add(f"{target}.{alias.name}")
    return {m for m in found if m.split(".")[0] == "floodsph"}


def _is_module(dotted: str) -> bool:
    rel = Path(*dotted.split(".")[1:]) if "." in dotted else Path()
    return (PACKAGE / rel).with_suffix(".py").is_file() or (PACKAGE / rel / "__init__.py").is_file()


def import_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """Edges between the nodes: ``graph[a]`` is the set of nodes that ``a`` imports."""
    graph: dict[str, set[str]] = {}
    for path in sorted(package.rglob("*.py")):
        source = _node(_module_name(path))
        assert source is not None
        graph.setdefault(source, set())
        for module in _imported_modules(path):
            if not _is_module(module):
                continue  # `from floodsph.x import name`: the name is not a module
            target = _node(module)
            if target is not None and target != source and target != "floodsph":
                graph[source].add(target)
    return graph


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan), each as a cycle."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
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
                components.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return [_one_cycle(graph, c) for c in components]


def _one_cycle(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """A closed path a -> ... -> a through the component, for the failure message."""
    members = set(component)
    start = component[0]
    # breadth-first search back to start within the component
    previous: dict[str, str] = {}
    frontier = [start]
    while frontier:
        nxt = []
        for v in frontier:
            for w in sorted(graph[v] & members):
                if w == start:
                    path = [v]
                    while path[-1] != start:
                        path.append(previous[path[-1]])
                    return [start, *reversed(path[:-1]), start] if v != start else [start, start]
                if w not in previous:
                    previous[w] = v
                    nxt.append(w)
        frontier = nxt
    return component


def test_the_graph_sees_the_subpackages():
    graph = import_graph()
    assert "floodsph.sph" in graph and "floodsph.model" in graph
    assert "floodsph.sph" in graph["floodsph.model"]


def test_no_cycle_between_subpackages():
    cycles = find_cycles(import_graph())
    message = "\n".join(" -> ".join(c) for c in cycles)
    assert not cycles, f"import cycles between subpackages:\n{message}"


def test_a_cycle_is_found_and_named():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert find_cycles(graph) == [["a", "b", "c", "a"]]
