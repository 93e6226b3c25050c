"""A small planning is tried on the event loop under a short leash, and a planning that slips it
runs again in a planning thread under what is left of its budget: the answer is the same, the
budget is the same, and work that sizes itself by its budget or waits on a worker process never
runs on the leash."""

from __future__ import annotations

import asyncio
import json
import threading
import time

import numpy as np
import pytest

from tests.paths import ROOT
from toptraj.planners.errors import BudgetExceeded
from toptraj.planners.execution.deadline import Deadline, Leash, LeashSlipped
from toptraj.service.planning import plan_request, worth_a_leash
from toptraj.service.schemas.trajectories import TrajectoryRequest
from toptraj.service.workers import PlanningWorkers

EXAMPLES = ROOT / "examples"


def _run(pool: PlanningWorkers, function, budget_s: float = 60.0, leashed: bool = True):
    async def main():
        try:
            return await pool.run(function, budget_s, leashed=leashed)
        finally:
            pool.close()

    return asyncio.run(main())


def _recording(calls: list, work=None):
    """A planning that records the thread and the deadline of each call, then does ``work``."""

    def function(deadline):
        calls.append((threading.current_thread(), deadline))
        return work(deadline) if work is not None else "answer"

    return function


def _checks_for(seconds: float):
    def work(deadline):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            deadline.check()
            time.sleep(0.001)
        return "answer"

    return work


def test_a_short_planning_runs_on_the_event_loop_under_the_leash():
    calls: list = []
    answer = _run(PlanningWorkers(workers=1, queue=2, leash_s=0.05), _recording(calls))
    assert answer == "answer"
    assert len(calls) == 1
    thread, deadline = calls[0]
    assert thread is threading.main_thread()  # asyncio.run's loop runs on the calling thread
    assert isinstance(deadline, Leash)


def test_a_planning_past_the_leash_runs_again_in_a_thread_under_the_rest_of_its_budget():
    calls: list = []
    answer = _run(PlanningWorkers(workers=1, queue=2, leash_s=0.02), _recording(calls, _checks_for(0.06)), budget_s=5.0)
    assert answer == "answer"  # within the budget: a planning past it gets the budget error
    assert [thread is threading.main_thread() for thread, _ in calls] == [True, False]
    tried, planned = calls[0][1], calls[1][1]
    assert isinstance(tried, Leash) and not isinstance(planned, Leash)
    # The thread's deadline is the request's, counted from its arrival: the try came out of it.
    assert planned.remaining() < 5.0 - 0.02


@pytest.mark.parametrize("asks", ["remaining", "on_cancel"])
def test_work_that_sizes_itself_by_its_budget_or_waits_on_a_process_never_runs_on_the_leash(asks):
    seen: list = []

    def work(deadline):
        if asks == "remaining":
            seen.append(deadline.remaining())
        else:
            with deadline.on_cancel(lambda: None):
                seen.append("waited")
        return "answer"

    calls: list = []
    started = time.monotonic()
    assert _run(PlanningWorkers(workers=1, queue=2, leash_s=0.05), _recording(calls, work), budget_s=30.0) == "answer"
    took = time.monotonic() - started
    assert [thread is threading.main_thread() for thread, _ in calls] == [True, False]
    assert len(seen) == 1  # only in the thread
    if asks == "remaining":  # the whole budget but what the run took so far, however slow the machine
        assert 30.0 - took <= seen[0] <= 30.0


def test_a_planning_over_its_budget_after_slipping_gets_the_budget_error_at_the_budget():
    """The budget error comes no earlier than the budget, and the planning in the thread, 10 s
    of work checking its deadline every millisecond, is stopped by its own check (an event,
    awaited with a hang guard only: how soon is a wall-clock figure of a loaded machine)."""
    calls: list = []
    stopped = threading.Event()

    def work(deadline):
        try:
            return _checks_for(10.0)(deadline)
        except BudgetExceeded:
            if not isinstance(deadline, Leash):
                stopped.set()
            raise

    started = time.monotonic()
    with pytest.raises(BudgetExceeded, match="time budget of 0.3 s") as raised:
        _run(PlanningWorkers(workers=1, queue=2, leash_s=0.02), _recording(calls, work), budget_s=0.3)
    assert stopped.wait(30.0)
    assert not isinstance(raised.value, LeashSlipped)
    assert time.monotonic() - started >= 0.3
    assert len(calls) == 2


def test_a_try_that_overran_the_whole_budget_is_the_budget_error_without_a_second_run():
    calls: list = []

    def overrun(deadline):
        time.sleep(0.08)  # a step that checks nothing, past the budget
        deadline.check()
        return "answer"

    with pytest.raises(BudgetExceeded, match="planning exceeded its time budget of 0.05 s") as raised:
        _run(PlanningWorkers(workers=1, queue=2, leash_s=0.02), _recording(calls, overrun), budget_s=0.05)
    assert not isinstance(raised.value, LeashSlipped)
    assert len(calls) == 1


def test_the_event_loop_is_free_while_a_slipped_planning_runs_in_its_thread():
    async def main():
        pool = PlanningWorkers(workers=1, queue=2, leash_s=0.01)
        loop_turned = threading.Event()

        def function(deadline):
            if isinstance(deadline, Leash):
                _checks_for(1.0)(deadline)
            # In the thread: done only once a task of the event loop has run.
            assert loop_turned.wait(10.0), "the event loop was held while the planning ran in its thread"
            return "answer"

        async def turn():
            while True:
                loop_turned.set()
                await asyncio.sleep(0.001)

        ticker = asyncio.create_task(turn())
        await asyncio.sleep(0)
        loop_turned.clear()
        try:
            return await pool.run(function, 30.0, leashed=True)
        finally:
            ticker.cancel()
            pool.close()

    assert asyncio.run(main()) == "answer"


def test_a_busy_pool_or_a_budget_within_the_leash_runs_the_planning_in_a_thread_at_once():
    # Budget no longer than the leash: the thread, whose budget's timer answers on time.
    calls: list = []
    _run(PlanningWorkers(workers=1, queue=2, leash_s=0.05), _recording(calls), budget_s=0.05)
    assert [thread is threading.main_thread() for thread, _ in calls] == [False]

    # Another planning under way: no try on the loop, whose turn-around serves the others.
    async def main():
        pool = PlanningWorkers(workers=2, queue=2, leash_s=0.05)
        gate, started = threading.Event(), threading.Event()

        def long(deadline):
            started.set()
            gate.wait(30)

        running = asyncio.create_task(pool.run(long, 60.0))
        while not started.is_set():
            await asyncio.sleep(0.001)
        calls.clear()
        await pool.run(_recording(calls), 60.0, leashed=True)
        gate.set()
        await running
        pool.close()

    asyncio.run(main())
    assert [thread is threading.main_thread() for thread, _ in calls] == [False]
    # Nor while the process holds other connections: its accept would wait for the try.
    calls.clear()
    _run(PlanningWorkers(workers=1, queue=2, leash_s=0.05, connections=lambda: 2), _recording(calls))
    assert [thread is threading.main_thread() for thread, _ in calls] == [False]
    # And a planning not marked leashed never runs on the loop.
    calls.clear()
    _run(PlanningWorkers(workers=1, queue=2, leash_s=0.05), _recording(calls), leashed=False)
    assert [thread is threading.main_thread() for thread, _ in calls] == [False]


def test_requests_arriving_together_all_go_to_the_threads_and_a_probe_among_them_is_answered_first():
    async def main():
        pool = PlanningWorkers(workers=2, queue=4, leash_s=0.05)
        calls: list = []
        order: list[str] = []

        async def probe():  # as /health: answered on the loop, without planning
            order.append("probe")

        both = threading.Barrier(2, timeout=10.0)  # the two plannings overlap

        def planning(deadline):
            order.append("planning")
            calls.append(threading.current_thread())
            if both is not None:
                both.wait()
            return "answer"

        together = await asyncio.gather(pool.run(planning, 60.0, leashed=True), pool.run(planning, 60.0, leashed=True))
        assert together == ["answer", "answer"]
        assert all(thread is not threading.main_thread() for thread in calls)
        # Alone, a planning is tried on the loop, after what came with it.
        calls.clear(), order.clear()
        both = None
        await asyncio.gather(pool.run(planning, 60.0, leashed=True), probe())
        pool.close()
        return calls, order

    calls, order = asyncio.run(main())
    assert calls == [threading.main_thread()]
    assert order == ["probe", "planning"]


def test_expect_slips_a_leash_only_for_a_step_that_would_end_past_it():
    leash = Leash(0.5)
    leash.expect(0.1)
    with pytest.raises(LeashSlipped, match="would run past the leash"):
        leash.expect(1.0)
    Deadline(0.5).expect(1.0)  # a budget stops work at its checks only


def _example(name: str) -> dict:
    return json.loads((EXAMPLES / name).read_text())


def test_only_small_waypoint_requests_on_a_checking_method_are_worth_a_leash():
    from toptraj import robots

    robots.load("ur5")
    typical = _example("ur5_spline.json")
    assert worth_a_leash(TrajectoryRequest.model_validate(typical))
    for example in ("ur5_spline_obstacles.json", "ur5_jerk_limited.json", "lecture_cartesian_line.json", "geering_free_motion.json"):
        assert not worth_a_leash(TrajectoryRequest.model_validate(_example(example))), example
    many = {**typical, "path": {**typical["path"], "waypoints": typical["path"]["waypoints"] * 3}}
    assert not worth_a_leash(TrajectoryRequest.model_validate(many))
    via = {**typical, "path": {**typical["path"], "interpolation": "via"}, "timing": {**typical["timing"], "method": "quintic"}}
    assert not worth_a_leash(TrajectoryRequest.model_validate(via))
    assert worth_a_leash(TrajectoryRequest.model_validate({**via, "path": typical["path"]}))
    toppra = {**typical, "timing": {**typical["timing"], "method": "toppra"}}  # its solve checks no deadline
    assert not worth_a_leash(TrajectoryRequest.model_validate(toppra))
    uploaded = {**typical, "robot": "not_built_here"}
    assert not worth_a_leash(TrajectoryRequest.model_validate(uploaded))


def test_a_planning_tried_on_the_leash_answers_as_one_under_its_budget():
    request = TrajectoryRequest.model_validate(_example("ur5_spline.json"))
    leashed = plan_request(request, Leash(10.0))
    budgeted = plan_request(request, Deadline(10.0))
    assert leashed.duration == budgeted.duration
    np.testing.assert_array_equal(leashed.samples.tau, budgeted.samples.tau)
    assert leashed.peak_utilization.keys() == budgeted.peak_utilization.keys()
    for kind, peaks in leashed.peak_utilization.items():
        np.testing.assert_array_equal(peaks, budgeted.peak_utilization[kind])
