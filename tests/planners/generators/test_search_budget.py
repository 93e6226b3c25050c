"""The global search obeys its budget and its memory: it stops within a second of its budget
wherever it is (in-process, at checks bounded in work), its memory is estimated from the
settings before any work (an upper bound of the spans it builds; 422 beyond the cap, naming the
largest value served), and a request's memory goes back when it ends."""

from __future__ import annotations

import re
import threading
import time

import numpy as np
import psutil
import pytest
from fastapi.testclient import TestClient

from toptraj import robots
from toptraj.planners import BudgetExceeded, Deadline
from toptraj.planners.collision import BoxObstacle
from toptraj.planners.generators.search.graph import SearchOptions, lattice_graph, roadmap_graph
from toptraj.planners.generators.search.memory import search_bytes, search_spans
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.generators.search.pieces import span_keys
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

UR5_START = [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
UR5_GOAL = [1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
#: Where the tool is halfway along the straight joint line (as in ``test_search``).
UR5_BOX = {"kind": "box", "center": [0.626, 0.109, 0.29], "size": [0.15, 0.15, 0.15]}
#: 64 small boxes on an arc the arm sweeps past: each distance computation and each
#: refinement round of the free space costs 64 obstacles' worth (the family where one round
#: ran for seconds past the budget).
ARC = tuple(
    BoxObstacle(np.array([0.62 * np.cos(a), 0.62 * np.sin(a) + 0.109, 0.29 + 0.1 * np.sin(5.0 * a)]), np.full(3, 0.05))
    for a in np.linspace(-0.6, 0.6, 64)
)


def _ur5_search(search: dict, budget_s: float, obstacles=(UR5_BOX,)) -> dict:
    return {
        "robot": "ur5",
        "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL, "obstacles": list(obstacles), "clearance": 0.02},
        "timing": {"method": "search", "search": search},
    }


@pytest.mark.parametrize("budget_s", [1.0, 4.0])
def test_the_search_stops_within_a_cpu_second_of_its_budget_in_process(budget_s):
    """Graph and free space at 1 s, the free space's refinement at 4 s (every span checked, not
    lazily: the lazy search of this case ends within 4 s): on the library's own
    thread (no worker process), so the checks inside the loops are what stops it. The work
    after the budget is counted in CPU-seconds of this process from the moment the budget
    passed to the search's end (wall time would count a busy machine's waits)."""
    robot = robots.load("ur5")
    deadline = Deadline(budget_s)
    outcome: list[BaseException] = []

    def search() -> None:
        try:
            global_search(
                robot, robot.limits, ("velocity", "acceleration", "torque"), np.array(UR5_START), np.array(UR5_GOAL),
                SearchOptions(tubes=1, lazy=False), True, ARC, 0.02, deadline,
            )
        except BaseException as error:  # noqa: BLE001 - examined below
            outcome.append(error)

    searching = threading.Thread(target=search)
    searching.start()
    searching.join(budget_s)
    at_budget = time.process_time()
    searching.join(120.0)  # a hang guard
    overrun = time.process_time() - at_budget
    assert not searching.is_alive()
    assert len(outcome) == 1 and isinstance(outcome[0], BudgetExceeded), outcome
    assert overrun < 1.0, f"the search computed {overrun:.2f} CPU-s past its budget of {budget_s} s"


def _spans(robot, start, goal, options, max_turn) -> int:
    """Spans of the search's graph, counted from its turns (what ``build_pieces`` builds)."""
    if options.graph == "lattice":
        graph = lattice_graph(robot, start, goal, options, True)
    else:
        graph = roadmap_graph(robot, start, goal, options, True, lambda q: np.ones(len(q), dtype=bool))
    turn_in, turn_out = graph.transitions(max_turn)
    return len(span_keys(graph.edge_from, graph.edge_to, graph.start, graph.goals, turn_in, turn_out)[0])


@pytest.mark.parametrize(
    "name, options, max_turn",
    [
        ("ur5", SearchOptions(graph="roadmap", roadmap_points=50, neighbors=5), 90.0),
        ("ur5", SearchOptions(graph="roadmap", roadmap_points=150, neighbors=10), 90.0),
        ("ur5", SearchOptions(graph="roadmap", roadmap_points=400, neighbors=20), 90.0),
        ("panda", SearchOptions(graph="roadmap", roadmap_points=300, neighbors=15), 90.0),
        ("geering_2r", SearchOptions(graph="roadmap", roadmap_points=300, neighbors=15), 90.0),
        ("geering_2r", SearchOptions(graph="lattice"), 45.0),
        ("geering_2r", SearchOptions(graph="lattice", cells=(40,)), 45.0),
        ("lecture_3r", SearchOptions(graph="lattice"), 45.0),
    ],
)
def test_the_estimate_bounds_the_spans_built_and_is_not_far_above(name, options, max_turn):
    robot = robots.load(name)
    start = np.zeros(robot.dof) if name != "ur5" else np.array(UR5_START)
    goal = np.full(robot.dof, 0.5) if name != "ur5" else np.array(UR5_GOAL)
    if name == "geering_2r":
        goal = np.array([0.76, 0.0])
    counted = _spans(robot, start, goal, options, max_turn)
    estimated = search_spans(robot, start, goal, options, True)
    assert counted <= estimated <= 3.0 * counted, (counted, estimated)


def test_a_search_beyond_the_memory_cap_gets_422_naming_the_largest_setting_served():
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=5.0))) as client:
        response = client.post("/v1/trajectories", json=_ur5_search({"roadmap_points": 2000, "neighbors": 50}, 5.0))
    assert response.status_code == 422, response.text[:300]
    detail = response.json()["detail"]
    assert "roadmap_points 2000 with neighbors 50" in detail and "GiB" in detail
    most = int(re.search(r"at most (\d+) roadmap points are served \(fewer than the 50 neighbors asked, which beyond the number of points join nothing more\)", detail).group(1))
    fewest = int(re.search(r"at most (\d+) neighbors with 2000 roadmap points", detail).group(1))
    robot = robots.load("ur5")
    start, goal = np.array(UR5_START), np.array(UR5_GOAL)
    cap = Settings().search_memory_bytes

    def served(points, neighbors):
        return search_bytes(robot, start, goal, SearchOptions(roadmap_points=points, neighbors=neighbors), True) <= cap

    # the advice is followable, and the largest: one more is refused
    assert 1 <= most < 2000 and served(most, 50) and not served(most + 1, 50)
    assert 1 <= fewest < 50 and served(2000, fewest) and not served(2000, fewest + 1)
    # the default searches are served: ur5's roadmap, and the three-joint lattice (1.45 GB)
    assert served(150, 10)
    lecture = robots.load("lecture_3r")
    assert search_bytes(lecture, np.zeros(3), np.array([1.5, 0.0, 0.0]), SearchOptions(), True) <= cap


def test_the_memory_of_a_search_goes_back_when_its_request_ends(monkeypatch):
    # a search of about 5 GB by its estimate (500 roadmap points, 12 neighbours, no obstacle)
    # under a cap raised to 8 GiB, stopped by a 3 s budget while it builds its spans and their
    # bounds (about 6 s; the spans' clearance is checked lazily, after the build)
    monkeypatch.setenv("TOPTRAJ_SEARCH_MEMORY_BYTES", str(8 * 2**30))
    process = psutil.Process()
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=3.0))) as client:
        client.get("/v1/robots/ur5")
        before = process.memory_info().rss
        response = client.post("/v1/trajectories", json=_ur5_search({"roadmap_points": 500, "neighbors": 12}, 3.0, ()))
        assert response.status_code == 504, response.text[:300]
        time.sleep(2.0)  # what the search would have built meanwhile, had it run on
        grown = process.memory_info().rss - before
    assert grown < 200e6, f"the process holds {grown / 1e6:.0f} MB more after the search"


def test_a_search_job_obeys_the_same_memory_cap(tmp_path):
    """Refused at submission with the synchronous endpoint's problem, before it is queued."""
    settings = Settings(preload_robots=False, data_dir=tmp_path, job_workers=1, job_budget_s=5.0)
    body = _ur5_search({"roadmap_points": 500, "neighbors": 50}, 5.0)
    with TestClient(create_app(settings)) as client:
        synchronous = client.post("/v1/trajectories", json=body)
        assert synchronous.status_code == 422 and "at most" in synchronous.json()["detail"]
        submitted = client.post("/v1/jobs", json={"trajectory": body})
        assert submitted.status_code == 422, submitted.text[:300]
        assert submitted.json() == synchronous.json()
        assert client.get("/v1/jobs").json()["jobs"] == []


def test_an_estimate_too_low_is_a_clear_error_not_the_system_killing_a_process(monkeypatch):
    # as if the estimate said 1 byte: the search's worker process gets 64 MB of room, runs out
    # while it builds its spans (about 0.5 GB), and the answer says so
    import toptraj.planners.generators.search.generator as search_generator

    monkeypatch.setattr(search_generator, "search_bytes", lambda *args, **kwargs: 1)
    monkeypatch.setattr(search_generator, "SEARCH_MEMORY_SLACK", 64 * 2**20)
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=30.0))) as client:
        response = client.post("/v1/trajectories", json=_ur5_search({}, 30.0, ()))
    assert response.status_code == 422, response.text[:300]
    assert response.json()["title"] == "Computation over its memory cap"
    assert "memory allowance" in response.json()["detail"] and "timing.search.roadmap_points" in response.json()["detail"]


def test_fewer_roadmap_points_than_neighbors_are_advised_as_such():
    """Under a small cap the largest roadmap served has fewer points than the neighbors asked:
    the advice says that neighbors beyond the points join nothing more (the roadmap caps them),
    not a count of neighbors that no point could have."""
    from toptraj.planners.generators.search.memory import over_memory
    from toptraj.service.problems import detail

    robot = robots.load("ur5")
    start, goal = np.array(UR5_START), np.array(UR5_GOAL)
    options = SearchOptions(roadmap_points=2000, neighbors=50)
    cap = search_bytes(robot, start, goal, SearchOptions(roadmap_points=30, neighbors=50), True)
    refusal = over_memory(robot, start, goal, options, True, cap)
    assert refusal.most_points is not None and refusal.most_points < 50
    text = detail(refusal)
    assert f"at most {refusal.most_points} roadmap points are served (fewer than the 50 neighbors asked, which beyond the number of points join nothing more)" in text, text
    assert "with 50 neighbors" not in text.split(";", 1)[1]


def test_a_comparison_answers_a_search_over_memory_in_the_search_s_entry():
    """As every other refusal of one method: the comparison is answered, the search's entry
    holding its 422 (it failed the whole comparison, and a compare job after its queue)."""
    body = _ur5_search({"roadmap_points": 2000, "neighbors": 50}, 5.0)
    compare = {"robot": body["robot"], "path": body["path"], "methods": ["collocation", "search"], "timing": {"search": body["timing"]["search"]}}
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=5.0))) as client:
        response = client.post("/v1/trajectories/compare", json=compare)
    assert response.status_code == 200, response.text[:300]
    search = response.json()["results"][1]
    assert search["method"] == "search" and search["error"]["status"] == 422, search
    assert "roadmap_points 2000 with neighbors 50" in search["error"]["detail"]


def test_a_search_whose_time_share_ends_before_any_grid_path_is_a_504(monkeypatch):
    """More time may find a grid path: a budget error (504, which a batch's --retry-failed plans
    again), not a 422 saying no path can be followed. Its share of the time is made nothing
    here (the first chunk of branch and bound finds no grid path of this problem)."""
    import toptraj.planners.generators.search.method as method

    monkeypatch.setattr(method, "SEARCH_SHARE", 0.0)
    robot = robots.load("ur5")
    box = BoxObstacle(np.array(UR5_BOX["center"]), np.array(UR5_BOX["size"]))
    with pytest.raises(BudgetExceeded) as stopped:
        global_search(robot, robot.limits, ("velocity", "acceleration"), np.array(UR5_START), np.array(UR5_GOAL),
                      obstacles=(box,), clearance=0.02, deadline=Deadline(60.0))
    assert "no grid path within its share of the time budget" in stopped.value.detail
    # a search without a budget runs to its end and finds one
    found = global_search(robot, robot.limits, ("velocity", "acceleration"), np.array(UR5_START), np.array(UR5_GOAL),
                          obstacles=(box,), clearance=0.02)
    assert found.result.tubes


def test_a_search_ended_by_max_expansions_is_a_422_naming_it():
    body = _ur5_search({"max_expansions": 1}, 20.0)
    with TestClient(create_app(Settings(preload_robots=False, plan_budget_s=20.0))) as client:
        response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text[:300]
    assert "no grid path within its max_expansions" in response.json()["detail"]
    assert "raise timing.search.max_expansions" in response.json()["detail"]


def test_a_comparison_answers_a_search_out_of_its_share_in_the_search_s_entry(monkeypatch):
    """A search whose share of the time ran out is a 504 of its own (``ShareSpent``); in a
    comparison it is the search's entry, the other methods answered (it failed the whole
    comparison as a 504 without any entry)."""
    import toptraj.service.planning as planning
    from toptraj.planners.errors import ShareSpent
    from toptraj.service.schemas.trajectories import CompareRequest

    planned = planning.plan_request

    def plan(request, *args, **kwargs):
        if request.timing.method == "search":
            raise ShareSpent("the search found no grid path within its share of the time budget (12 partial paths expanded)")
        return planned(request, *args, **kwargs)

    monkeypatch.setattr(planning, "plan_request", plan)
    body = {"robot": "ur5", "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL}, "methods": ["collocation", "search"],
            "timing": {"constraints": ["velocity", "acceleration"]}}
    results = planning.compare_request(CompareRequest.model_validate(body), Deadline(120.0))["results"]
    assert results[1]["method"] == "search" and results[1]["error"]["status"] == 504, results[1]
    assert "share of the time budget" in results[1]["error"]["detail"]
    assert results[0]["method"] == "collocation" and results[0]["duration"] > 0
