"""The cell request (two ur5 facing each other with crossing paths, ``examples/cell_two_ur5.json``)
against one bare toppra solve (its own API, 100 intervals, ``anchors.bare_toppra``) on the first
arm's path, interleaved: the library call, the request over HTTP (TestClient), and the same cell
with a third ur5 at the table's side (prioritized planning over every order of the arms).

    python benchmarks/cell.py [--rounds 5]

Prints the medians and the ratios to the anchor, and the cell's answer (schedule, durations).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from anchors import bare_toppra  # noqa: E402
from fastapi.testclient import TestClient  # noqa: E402

from toptraj import robots  # noqa: E402
from toptraj.planners.execution.deadline import Deadline  # noqa: E402
from toptraj.service.app import create_app  # noqa: E402
from toptraj.service.cells import plan_cell  # noqa: E402
from toptraj.service.schemas.cells import CellRequest  # noqa: E402
from toptraj.service.settings import Settings  # noqa: E402

BODY = json.loads((ROOT / "examples" / "cell_two_ur5.json").read_text())
#: A third ur5 at the table's side, turned a quarter about z, on the first arm's path.
QUARTER = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
THREE = BODY | {"arms": BODY["arms"] + [BODY["arms"][0] | {"base": {"position": [0.6, 1.1, 0.0], "rotation": QUARTER}}]}


def _timed(function) -> float:
    started = time.perf_counter()
    function()
    return time.perf_counter() - started


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    robot = robots.load("ur5")
    waypoints = np.array(BODY["arms"][0]["waypoints"], dtype=float)
    request, three = CellRequest.model_validate(BODY), CellRequest.model_validate(THREE)
    anchor, library, http, library3 = [], [], [], []
    settings = Settings(preload_robots=False, plan_budget_s=300.0, data_dir=Path(tempfile.mkdtemp()))
    with TestClient(create_app(settings)) as client:
        assert client.post("/v1/cells", json=BODY).status_code == 200  # warm: capsules, kernels
        for _ in range(args.rounds):
            anchor.append(_timed(lambda: bare_toppra(robot, waypoints)))
            library.append(_timed(lambda: plan_cell(request, Deadline(300.0))))
            http.append(_timed(lambda: client.post("/v1/cells", json=BODY)))
            library3.append(_timed(lambda: plan_cell(three, Deadline(300.0))))
    base = statistics.median(anchor)
    answer = plan_cell(request, Deadline(300.0))
    print(f"bare toppra (one arm, 100 intervals): {base * 1e3:.1f} ms")
    print(f"cell, library: {statistics.median(library) * 1e3:.0f} ms = {statistics.median(library) / base:.0f}x bare toppra")
    print(f"cell, HTTP:    {statistics.median(http) * 1e3:.0f} ms = {statistics.median(http) / base:.0f}x bare toppra")
    print(
        f"three arms, library: {statistics.median(library3) * 1e3:.0f} ms = {statistics.median(library3) / base:.0f}x bare toppra"
    )
    print(
        f"cell: {answer['schedule']}, duration {answer['duration']:.4f} s, own optima {answer['solo_durations']}, "
        f"one after the other {answer['sequential_duration']:.4f} s, time lost {answer['time_lost']:.4f} s"
    )
    answer = plan_cell(three, Deadline(300.0))
    print(
        f"three arms: {answer['schedule']}, duration {answer['duration']:.4f} s, one after the other {answer['sequential_duration']:.4f} s"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
