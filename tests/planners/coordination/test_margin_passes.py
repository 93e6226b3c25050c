"""The margin-free second pass of ``coordinate`` (its ``MARGINS``) finds which cells are free
again from the distances of the first, not the whole distance grid anew."""

from __future__ import annotations

import importlib

from tests.planners.coordination.cells import facing_cell
from toptraj.planners.coordination import diagram
from toptraj.planners.coordination.diagram import GRID

coordinate_module = importlib.import_module("toptraj.planners.coordination.coordinate")


def test_the_second_pass_reuses_the_distance_grid(monkeypatch):
    rows, margins = [], []
    original_distances, original_diagram = diagram.pair_distances, coordinate_module.coordination_diagram

    def counted(*args, **kwargs):
        rows.append(1)
        return original_distances(*args, **kwargs)

    def diagram_at(*args, **kwargs):
        margins.append(kwargs["margin"])
        return original_diagram(*args, **kwargs)

    monkeypatch.setattr(diagram, "pair_distances", counted)
    monkeypatch.setattr(coordinate_module, "coordination_diagram", diagram_at)
    # a first margin no cell holds: every candidate of the first pass fails, the second pass finds one
    monkeypatch.setattr(coordinate_module, "MARGINS", (10.0, 0.0))
    found = coordinate_module.coordinate(facing_cell())
    assert margins == [10.0, 0.0] and found.schedule.duration > 0.0
    assert len(rows) == GRID + 1 + 1  # the grid's rows once, and the starts' check
