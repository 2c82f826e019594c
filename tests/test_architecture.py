"""The package's shape: no import cycle anywhere in robot_lab/, no module over 600 lines.

What counts as an import (decided here, documented in docs/architecture.md):
- every `import x` / `from x import y` in a module, at any depth, *including imports inside
  functions*: a function-level import delays a dependency, it does not remove it, so two
  modules that reach each other that way are still one tangled unit;
- except imports under `if TYPE_CHECKING:`, which never run (they exist for annotations);
- `from pkg import name` is an edge to `pkg.name` when that is a module, else to `pkg`;
- names loaded through a lazy `__getattr__` table or `importlib.import_module('...')` are
  strings, not imports, and do not count (that is what the lazy tables are for).
A package's `__init__` is only an edge when something imports the package itself.
The same graph, with modules collapsed into their top-level package (robot_lab.pkg,
robot_lab.env, ...), must have no cycle either.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

pytestmark = pytest.mark.no_ros  # reads files only: no ROS_DOMAIN_ID slot

PACKAGE = Path(__file__).resolve().parent.parent / 'robot_lab'
MAX_LINES = 600


def _modules() -> dict[str, Path]:
    found: dict[str, Path] = {}
    for path in sorted(PACKAGE.rglob('*.py')):
        relative = path.relative_to(PACKAGE.parent).with_suffix('')
        parts = list(relative.parts)
        if parts[-1] == '__init__':
            parts.pop()
        if any(part.startswith('.') for part in parts):
            continue
        found['.'.join(parts)] = path
    return found


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == 'TYPE_CHECKING') or (
        isinstance(test, ast.Attribute) and test.attr == 'TYPE_CHECKING')


def _imports(tree: ast.AST, module: str, is_package: bool) -> list[tuple[str, list[str]]]:
    """(imported module, names taken from it) for every import that runs."""
    found: list[tuple[str, list[str]]] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            for other in node.orelse:
                visit(other)
            return
        if isinstance(node, ast.Import):
            found.extend((alias.name, []) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                parts = module.split('.')
                if not is_package:
                    parts = parts[:-1]
                parts = parts[:len(parts) - (node.level - 1)]
                base = '.'.join(parts + ([base] if base else []))
            found.append((base, [alias.name for alias in node.names]))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


@functools.cache
def import_graph() -> dict[str, set[str]]:
    """robot_lab module -> the robot_lab modules it imports."""
    modules = _modules()
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        for target, names in _imports(tree, name, path.name == '__init__.py'):
            if not target.startswith('robot_lab'):
                continue
            submodules = [f'{target}.{n}' for n in names if f'{target}.{n}' in modules]
            if submodules:
                graph[name].update(submodules)
            if len(submodules) < len(names) or not names:
                # a plain `import a.b.c`, or names that are not modules: the module itself
                while target not in modules and '.' in target:
                    target = target.rsplit('.', 1)[0]
                if target in modules:
                    graph[name].add(target)
        graph[name].discard(name)
    return graph


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    result: list[list[str]] = []
    counter = 0

    def connect(start: str) -> None:
        nonlocal counter
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    result.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            connect(node)
    return sorted(result)


def _path_through(graph: dict[str, set[str]], component: list[str]) -> str:
    """One concrete cycle inside a component, for the failure message."""
    members = set(component)
    start = component[0]
    path = [start]
    seen = {start}
    node = start
    while True:
        nxt = sorted(graph[node] & members)
        back = [n for n in nxt if n == start]
        if back and len(path) > 1:
            return ' -> '.join([*path, start])
        fresh = [n for n in nxt if n not in seen]
        if not fresh:
            return ' -> '.join([*path, nxt[0]]) if nxt else ' -> '.join(path)
        node = fresh[0]
        path.append(node)
        seen.add(node)


def test_no_import_cycle() -> None:
    graph = import_graph()
    assert 'robot_lab.launch.api' in graph  # the walk found the package
    cycles = find_cycles(graph)
    assert not cycles, 'import cycles in robot_lab/:\n' + '\n'.join(
        f'  {", ".join(c)}\n    e.g. {_path_through(graph, c)}' for c in cycles)


def test_no_cycle_between_packages() -> None:
    """`robot_lab.env` and `robot_lab.pkg` (or any two top-level units) never reach each other."""

    def unit(module: str) -> str:
        return '.'.join(module.split('.')[:2])

    graph: dict[str, set[str]] = {}
    for module, targets in import_graph().items():
        graph.setdefault(unit(module), set()).update(
            unit(t) for t in targets if unit(t) != unit(module))
    cycles = find_cycles(graph)
    assert not cycles, 'packages that import each other:\n' + '\n'.join(
        f'  {_path_through(graph, c)}' for c in cycles)


def test_cycle_finder_sees_a_cycle_through_a_function_level_import() -> None:
    source_a = 'from robot_lab import b\n'
    source_b = 'def f():\n    import robot_lab.a\n'
    source_c = 'from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import robot_lab.a\n'
    graph: dict[str, set[str]] = {}
    for name, source in (('a', source_a), ('b', source_b), ('c', source_c)):
        edges = {t.replace('robot_lab.', '') for t, _ in _imports(ast.parse(source), name, False)
                 if t.startswith('robot_lab.')}
        edges |= {n for t, names in _imports(ast.parse(source), name, False)
                  if t == 'robot_lab' for n in names}
        graph[name] = edges
    assert graph == {'a': {'b'}, 'b': {'a'}, 'c': set()}
    assert find_cycles(graph) == [['a', 'b']]


def test_no_module_over_600_lines() -> None:
    long = {str(path.relative_to(PACKAGE.parent)): n for path in PACKAGE.rglob('*.py')
            if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, f'modules over {MAX_LINES} lines (split them by concern): {long}'
