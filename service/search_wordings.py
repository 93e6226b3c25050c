"""The service's words for the global search's refusals (a graph over the memory cap, no grid
path found, a search cut short), as ``toptraj.service.wordings`` words the other errors
(``SEARCH_WORDING`` is part of its ``WORDING``)."""

from __future__ import annotations

import math
from collections.abc import Callable


def _about(facts: dict) -> str:
    return f"about {facts['estimate'] / 2**30:.3g} GiB, above the cap of {facts['cap'] / 2**30:.3g} GiB per search"


def _lattice_over_memory(facts: dict) -> str:
    cells = facts["largest"]
    advice = f"at most {cells} cells per joint are served" if cells is not None else "no lattice fits: use timing.search.graph 'roadmap'"
    return (
        f"{facts['field']} gives a lattice of {facts['shape']} grid points on a {facts['dof']}-joint arm, which needs "
        f"{_about(facts)}; {advice}"
    )


def _roadmap_over_memory(facts: dict) -> str:
    points, neighbors = facts["points"], facts["neighbors"]
    served = []
    most_points = facts["most_points"]
    if most_points is not None and most_points < neighbors:  # a point has fewer others than neighbors asks
        served.append(f"at most {most_points} roadmap points are served (fewer than the {neighbors} neighbors asked, "
                      "which beyond the number of points join nothing more)")
    elif most_points is not None:
        served.append(f"at most {most_points} roadmap points are served with {neighbors} neighbors")
    if facts["most_neighbors"] is not None:
        served.append(f"at most {facts['most_neighbors']} neighbors with {points} roadmap points")
    return (
        f"{facts['field']} {points} with neighbors {neighbors} on a {facts['dof']}-joint arm needs {_about(facts)}; "
        + ("; ".join(served) if served else "lower timing.search.neighbors and roadmap_points")
    )


def _search_incomplete(facts: dict) -> str:
    """A search ended by its max_expansions or its node table's memory (its time share ending is
    a 504, ``BudgetExceeded``)."""
    smaller = "timing.search.roadmap_points or timing.search.neighbors" if facts["graph"] == "roadmap" else "timing.search.cells"
    expanded = facts["statistics"].expanded
    if facts.get("stopped") == "memory":
        return (
            f"the search found no grid path before its node table reached its memory ({expanded} partial paths expanded): "
            f"use fewer {smaller}"
        )
    return (
        f"the search found no grid path within its max_expansions ({expanded} partial paths expanded): "
        f"raise timing.search.max_expansions or use fewer {smaller}"
    )


def _no_grid_path(facts: dict) -> str:
    stats = facts["statistics"]
    finer = (
        "raise timing.search.roadmap_points or timing.search.neighbors (within the memory cap), try another "
        "timing.search.seed"
        if facts["graph"] == "roadmap"
        else "refine timing.search.cells"
    )
    below = f" faster than {facts['cap']:.4g} s" if math.isfinite(facts["cap"]) else ""
    return (
        f"the search found no grid path from start to goal{below} that keeps the clearance and the limits "
        f"({stats.grid_points} grid points, {stats.removed_by_obstacles} pieces of path removed by obstacles, "
        f"{stats.points_blocked} grid points blocked): {finer}, widen timing.search.margin, or move the obstacles"
    )


SEARCH_WORDING: dict[str, str | Callable[[dict], str]] = {
    "lattice_over_memory": _lattice_over_memory,
    "roadmap_over_memory": _roadmap_over_memory,
    "search_incomplete": _search_incomplete,
    "no_grid_path": _no_grid_path,
}
