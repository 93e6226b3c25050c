"""Sizes of the tree: modules and lines per folder, modules over 400 lines, functions over 60
lines (compiled kernels apart), and functions of planners/ and robots/ without annotations.

Run from the repository root: ``python3 docs/measures/sizes.py``.
"""

from __future__ import annotations

import ast
import pathlib

ROOTS = ("compiled", "robots", "planners", "service", "client", "tests", "benchmarks")


def main() -> None:
    print(f"{'folder':28s} modules  lines")
    for root in ROOTS:
        for folder in sorted({p.parent for p in pathlib.Path(root).rglob("*.py")}):
            files = sorted(folder.glob("*.py"))
            print(f"{str(folder) + '/':28s} {len(files):7d} {sum(len(f.read_text().splitlines()) for f in files):6d}")
    long_modules, long_functions, bare, partial = [], [], 0, 0
    for root in ("compiled", "robots", "planners", "service", "client"):
        for path in sorted(pathlib.Path(root).rglob("*.py")):
            text = path.read_text()
            if len(text.splitlines()) > 400:
                long_modules.append(f"{path} ({len(text.splitlines())})")
            for node in ast.walk(ast.parse(text)):
                if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                    continue
                compiled = any("jit" in ast.unparse(d) for d in node.decorator_list)
                length = (node.end_lineno or node.lineno) - node.lineno + 1
                if length > 60 and not compiled:
                    long_functions.append(f"{length:4d} {path}:{node.lineno} {node.name}")
                if root in ("robots", "planners"):
                    arguments = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
                    arguments = [a for a in arguments if a.arg not in ("self", "cls")]
                    annotated = [a for a in arguments if a.annotation is not None]
                    if not annotated and node.returns is None:
                        bare += 1
                    elif not node.name.startswith("_") and (len(annotated) < len(arguments) or node.returns is None):
                        partial += 1
    print("modules over 400 lines:", ", ".join(long_modules) or "none")
    print(f"functions over 60 lines, compiled kernels apart: {len(long_functions)}")
    for line in sorted(long_functions, reverse=True):
        print("  ", line)
    print(f"planners/ and robots/: {bare} functions without any annotation, {partial} public ones partly annotated")


if __name__ == "__main__":
    main()
