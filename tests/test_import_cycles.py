"""No import cycle between modules of different folders, and none at run time at all, as
``docs/measures/imports.py`` reads them (imports inside functions and for annotations count).
The limit gate once reached the runner's accuracy module, which closed a cycle through the
results, the generators' reports and the problem room."""

from __future__ import annotations

import importlib.util

import pytest

from tests.paths import ROOT


@pytest.fixture(scope="module")
def measure():
    spec = importlib.util.spec_from_file_location("imports_measure", ROOT / "docs" / "measures" / "imports.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_module_cycle_lies_within_one_folder(measure, monkeypatch):
    monkeypatch.chdir(ROOT)
    across = [cycle for cycle in measure.cycles(measure.import_graph()) if len({measure.folder(m) for m in cycle}) > 1]
    assert across == []


def test_no_module_cycle_at_run_time(measure, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert measure.cycles(measure.import_graph(type_checking=False)) == []


def test_the_limit_gate_imports_nothing_of_the_runner(measure, monkeypatch):
    monkeypatch.chdir(ROOT)
    graph = measure.import_graph()
    assert {target for target in graph["planners.checks.gate"] if target.startswith("planners.runner")} == set()
