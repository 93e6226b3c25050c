"""The import graph of robots/, planners/, service/ and client/, read from the source (ast):
cycles between modules and between folders, imports from a lower package to a higher one, and
the imports of planners/ that would point upward once its modules sit in the rooms of
``docs/design.md`` (those need a change of design, not a move).

Run from the repository root: ``python3 docs/measures/imports.py``.
"""

from __future__ import annotations

import ast
import collections
import pathlib
import sys

ROOTS = ("compiled", "robots", "planners", "service", "client")
#: Layer of each top-level package: an import may point down or sideways, never up.
PACKAGE_LAYER = {"compiled": -1, "robots": 0, "planners": 1, "service": 2, "client": 2}
#: Today's planners module (or folder) -> its room in the target tree.
ROOM = {
    "toptraj.planners.runner": "runner",
    "toptraj.planners.problem": "problem",
    "toptraj.planners.generators": "generators",
    "toptraj.planners.checks": "checks",
    "toptraj.planners.timing.laws": "timing",
    "toptraj.planners.timing.jerk": "timing",
    "toptraj.planners.timing.phase_plane": "timing",
    "toptraj.planners.constraints": "constraints",
    "toptraj.planners.execution": "execution",
    "planners": "runner", "toptraj.planners.plan": "runner", "toptraj.planners.runner.given_path": "runner", "toptraj.planners.runner.run": "runner", "toptraj.planners.runner.answer": "runner",
    "toptraj.planners.errors": "errors",
    "toptraj.planners.execution.deadline": "execution", "toptraj.planners.execution.isolated": "execution", "toptraj.planners.execution.threads": "execution",
    "toptraj.planners.kinematics": "kinematics", "toptraj.planners.paths": "paths", "toptraj.planners.paths.grid": "paths", "toptraj.planners.collision": "collision",
    "toptraj.planners.constraints.path_constraints": "constraints", "toptraj.planners.constraints.assembly_kernels": "constraints", "toptraj.planners.constraints.admissible": "constraints",
    "toptraj.planners.constraints.admissible_kernels": "constraints", "toptraj.planners.constraints.tool_speed": "constraints", "toptraj.planners.constraints.torque_interpolation": "constraints",
    "toptraj.planners.timing": "timing", "toptraj.planners.timing.phase_plane.sweep_kernels": "timing", "toptraj.planners.timing.phase_plane.refinement_kernels": "timing",
    "toptraj.planners.timing.phase_plane.split_kernels": "timing",
    "toptraj.planners.checks.limit_check": "checks", "toptraj.planners.checks.limit_kernels": "checks", "toptraj.planners.checks.gate": "checks",
    "toptraj.planners.trajectory": "checks",
    "toptraj.planners.generators.via_points": "generators", "toptraj.planners.generators.unsynchronized": "generators",
    "toptraj.planners.timing.collocation_method": "generators", "toptraj.planners.generators.collocation": "generators", "toptraj.planners.generators.search": "generators",
    "toptraj.planners.problem.requests": "problem", "toptraj.planners.problem.waypoints": "problem", "toptraj.planners.problem.boundary": "problem",
    "toptraj.planners.problem.ranges": "problem", "toptraj.planners.results": "results",
}
#: Layer of each room (docs/design.md, "Layers"): lower numbers are imported by higher ones.
ROOM_LAYER = {
    "errors": 0, "execution": 1, "kinematics": 2, "paths": 3, "collision": 4, "constraints": 5, "timing": 6,
    "checks": 7, "problem": 8, "generators": 9, "results": 10, "runner": 11,
}


# the modules are read under their folders' names: the one import name's prefix is dropped
ROOM = {name.removeprefix("toptraj."): target for name, target in ROOM.items()}


def module_name(path: pathlib.Path) -> str:
    parts = list(path.with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(tree: ast.AST, type_checking: bool):
    """The import statements of ``tree``; without those under ``if TYPE_CHECKING:`` unless
    ``type_checking``."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If) and not type_checking and "TYPE_CHECKING" in ast.unparse(node.test):
            yield from (child for branch in node.orelse for child in _imports(ast.Module([branch], []), type_checking))
        else:
            yield from _imports(node, type_checking)


def import_graph(type_checking: bool = True) -> dict[str, set[str]]:
    """Module -> the project modules it imports (at its top or inside functions; with
    ``type_checking``, those imported for annotations only too)."""
    modules = {module_name(p): p for root in ROOTS for p in pathlib.Path(root).rglob("*.py")}

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {}
    for module, path in modules.items():
        targets = set()
        for node in _imports(ast.parse(path.read_text()), type_checking):
            if isinstance(node, ast.Import):
                names = [alias.name.removeprefix("toptraj.") for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [f"{node.module}.{alias.name}".removeprefix("toptraj.") for alias in node.names]
            else:
                continue
            targets |= {t for t in map(resolve, names) if t is not None and t != module}
        graph[module] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one node (Tarjan)."""
    sys.setrecursionlimit(10_000)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for target in graph.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in list(graph):
        if node not in index:
            visit(node)
    return found


def folder(module: str) -> str:
    return module if pathlib.Path(*module.split(".")).is_dir() else module.rpartition(".")[0]


def room(module: str) -> str:
    while module not in ROOM:
        module = module.rpartition(".")[0]
    return ROOM[module]


def main() -> None:
    graph = import_graph()
    print(f"{len(graph)} modules, {sum(map(len, graph.values()))} imports between them")
    print("module cycles:", cycles(graph) or "none")
    print("module cycles at run time (imports for annotations only left out):", cycles(import_graph(type_checking=False)) or "none")
    folders: dict[str, set[str]] = collections.defaultdict(set)
    for module, targets in graph.items():
        folders[folder(module)] |= {folder(t) for t in targets if folder(t) != folder(module)}
    print("folder cycles:", cycles(folders) or "none")
    upward = [(m, t) for m, ts in graph.items() for t in ts if PACKAGE_LAYER[t.split(".")[0]] > PACKAGE_LAYER[m.split(".")[0]]]
    print("imports from a lower top-level package to a higher one:", upward or "none")
    against = sorted(
        (m, t) for m, ts in graph.items() if m.startswith("planners") for t in ts
        if t.startswith("planners") and ROOM_LAYER[room(t)] > ROOM_LAYER[room(m)]
    )
    print(f"planners imports pointing upward once moved to the target rooms: {len(against)}")
    for module, target in against:
        print(f"  {module} [{room(module)}] -> {target} [{room(target)}]")


if __name__ == "__main__":
    main()
