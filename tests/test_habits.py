"""Habits CI keeps: mypy checks the bodies of every function, every public function of the
library (``planners/``, ``robots/``, ``compiled/``) is annotated, and the runtime image carries no browser (the
``test`` stage of the Dockerfile adds it, and CI runs the suite there)."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import tomllib

import pytest

from tests.paths import ROOT

LIBRARY = ("planners", "robots", "compiled")


def _public_functions(tree: ast.Module):
    """(qualified name, node) of the module's public functions and of its public classes'
    public and special methods; compiled kernels (numba's ``jit``) take numba's arrays and are
    left out, as nested functions are."""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and not node.name.startswith("_"):
            if not any("jit" in ast.unparse(decorator) for decorator in node.decorator_list):
                yield node.name, node
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            for method in node.body:
                if isinstance(method, ast.FunctionDef | ast.AsyncFunctionDef):
                    dunder = method.name.startswith("__") and method.name.endswith("__")
                    if dunder or not method.name.startswith("_"):
                        yield f"{node.name}.{method.name}", method


def _unannotated(function: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> list[str]:
    """The names of ``function``'s parameters without an annotation, and ``return`` when its
    return type is missing (``__init__`` needs none once a parameter is annotated, as for mypy)."""
    arguments = function.args
    named = [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs]
    if method and named and named[0].arg in ("self", "cls") and "staticmethod" not in map(ast.unparse, function.decorator_list):
        named = named[1:]
    starred = [argument for argument in (arguments.vararg, arguments.kwarg) if argument is not None]
    missing = [argument.arg for argument in [*named, *starred] if argument.annotation is None]
    annotated = any(argument.annotation is not None for argument in [*named, *starred])
    if function.returns is None and not (function.name == "__init__" and annotated):
        missing.append("return")
    return missing


def test_every_public_function_of_the_library_is_annotated():
    missing = {}
    for package in LIBRARY:
        for path in sorted((ROOT / package).rglob("*.py")):
            tree = ast.parse(path.read_text())
            for name, function in _public_functions(tree):
                gaps = _unannotated(function, method="." in name)
                if gaps:
                    missing[f"{path.relative_to(ROOT).as_posix()}:{name}"] = gaps
    assert missing == {}


def test_a_function_without_annotations_is_found():
    tree = ast.parse("def f(a, b: int):\n    pass\n\nclass C:\n    def __init__(self, x: int):\n        pass\n\n    def m(self, y) -> None:\n        pass\n")
    found = {name: _unannotated(node, "." in name) for name, node in _public_functions(tree)}
    assert found == {"f": ["a", "return"], "C.__init__": [], "C.m": ["y"]}


def test_mypy_checks_untyped_bodies_and_ruff_asks_for_annotations_and_docstrings():
    settings = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert settings["tool"]["mypy"]["check_untyped_defs"] is True
    lint = settings["tool"]["ruff"]["lint"]
    assert {"ANN201", "ANN204", "D"} <= set(lint["select"])
    # on the library only: outside planners/, robots/ and compiled/ both families are ignored
    assert set(lint["extend-per-file-ignores"]["!{planners,robots,compiled}/**"]) == {"ANN", "D"}


def _stages(dockerfile: str) -> list[tuple[str, str | None, str]]:
    """(base, name, body) of each stage of ``dockerfile``, continuation lines joined."""
    text = re.sub(r"\\\n", " ", dockerfile)
    text = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))
    parts = re.split(r"^FROM\s+", text, flags=re.M)[1:]
    stages = []
    for part in parts:
        head, _, body = part.partition("\n")
        words = head.split()
        name = words[2] if len(words) >= 3 and words[1].upper() == "AS" else None
        stages.append((words[0], name, body))
    return stages


def test_the_runtime_image_has_no_browser_and_the_test_stage_adds_it():
    stages = _stages((ROOT / "Dockerfile").read_text())
    by_name = {name: (base, body) for base, name, body in stages}
    assert {"runtime", "test"} <= set(by_name)
    runtime = by_name["runtime"][1]
    assert "libgomp1" in runtime and "chromium" not in runtime and "playwright install" not in runtime
    base, test = by_name["test"]
    assert base == "runtime"
    assert re.search(r"apt-get install[^\n]*\bchromium\b[^\n]*\blibatomic1\b", test)
    assert re.search(r'^CMD \["python", "-m", "pytest"\]', test, re.M)
    # without --target, the build gives the runtime image: the last stage is the runtime stage itself
    last_base, _, last_body = stages[-1]
    assert last_base == "runtime" and last_body.strip() == ""


def test_ci_runs_the_suite_in_the_test_image_and_checks_the_runtime_image_for_a_browser():
    run, container = ROOT / ".ci" / "run", ROOT / ".ci" / "container.sh"
    if not run.exists():
        pytest.skip("the image leaves .ci out (.dockerignore); the host run checks it")
    assert 'bash "$ROOT/.ci/container.sh"' in run.read_text()
    assert "dockerd" not in run.read_text() and "docker build" not in run.read_text()  # the plumbing lives in container.sh
    script = container.read_text()
    assert '--target test -t "$TEST_IMAGE"' in script and '--target runtime -t "$IMAGE"' in script
    assert 'docker run --network none --rm "$IMAGE" which chromium' in script
    assert re.search(r'docker run [^\n]*"\$TEST_IMAGE" python -m pytest', script)
    for path in (run, container):
        subprocess.run(["bash", "-n", str(path)], check=True)
    if shutil.which("shellcheck"):
        subprocess.run(["shellcheck", str(run), str(container)], check=True)
