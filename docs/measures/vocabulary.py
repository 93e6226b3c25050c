"""The request's vocabulary and HTTP statuses in the library: string literals (an f-string
counted once, docstrings left out) that name a request field (``timing.x``, ``path.x``,
``output.x``), literal ``"timing.`` / ``"path.`` / ``"output.`` openings, and ``status = N``
class attributes.

Run from the repository root: ``python3 docs/measures/vocabulary.py [folder ...]`` (default:
planners robots).
"""

from __future__ import annotations

import ast
import collections
import pathlib
import re
import sys

FIELD = re.compile(r"(?<![\w.])(timing|path|output)\.[a-z_]+")
OPENING = re.compile(r"""f?["'](timing|path|output)\.""")


def _docstrings(tree: ast.AST) -> set[int]:
    owners = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
    return {
        id(node.body[0].value) for node in ast.walk(tree)
        if isinstance(node, owners) and node.body and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }


def main(roots: list[str]) -> None:
    strings: collections.Counter[str] = collections.Counter()
    openings: collections.Counter[str] = collections.Counter()
    statuses = []
    for root in roots:
        for path in sorted(pathlib.Path(root).rglob("*.py")):
            text = path.read_text()
            tree = ast.parse(text)
            docs = _docstrings(tree)
            parts = {id(v) for node in ast.walk(tree) if isinstance(node, ast.JoinedStr) for v in node.values}
            for node in ast.walk(tree):
                if isinstance(node, ast.JoinedStr):
                    literal = "".join(v.value for v in node.values if isinstance(v, ast.Constant))
                elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs | parts:
                    literal = node.value
                else:
                    continue
                if FIELD.search(literal):
                    strings[str(path)] += 1
            openings[str(path)] += len(OPENING.findall(text))
            statuses += [
                f"{path}:{node.lineno} status = {ast.unparse(node.value)}" for node in ast.walk(tree)
                if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, int)
                and any(isinstance(t, ast.Name) and t.id == "status" for t in node.targets)
            ] + [
                f"{path}:{node.lineno} status: int = {ast.unparse(node.value)}" for node in ast.walk(tree)
                if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.target.id == "status"
                and isinstance(node.value, ast.Constant) and isinstance(node.value.value, int)
            ]
    for name, count in strings.most_common():
        print(f"{count:4d} {name}")
    print(f"{sum(strings.values())} strings naming a request field, in {len(strings)} modules")
    print(f"{sum(openings.values())} literal openings \"timing. \"path. \"output., in {sum(1 for c in openings.values() if c)} modules")
    print(f"{len(statuses)} HTTP statuses:")
    for line in statuses:
        print("  ", line)


if __name__ == "__main__":
    main(sys.argv[1:] or ["planners", "robots"])
