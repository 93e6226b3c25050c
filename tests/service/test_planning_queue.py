"""Requests waiting for a planning thread get one in the order they came: a request arriving
as a slot frees never takes it ahead of requests already waiting."""

from __future__ import annotations

import asyncio
import threading
import time

from toptraj.service.workers import PlanningWorkers


async def _order_of_service() -> list[str]:
    pool = PlanningWorkers(workers=1, queue=4)
    order: list[str] = []
    started, gate = threading.Event(), threading.Event()

    def first(deadline):
        started.set()
        gate.wait(30)
        order.append("first")

    def named(name):
        return lambda deadline: order.append(name)

    running = asyncio.create_task(pool.run(first, 60))
    while not started.is_set():
        await asyncio.sleep(0.001)
    waiting = [asyncio.create_task(pool.run(named(name), 60)) for name in ("w1", "w2")]
    for _ in range(5):
        await asyncio.sleep(0)  # both are queued behind the running planning
    gate.set()
    # Hold the event loop until the slot is free again, then let a new request arrive at once.
    while not pool._slots.acquire(blocking=False):
        time.sleep(0.001)
    pool._slots.release()
    late = asyncio.create_task(pool.run(named("late"), 60))
    await asyncio.gather(running, *waiting, late)
    pool.close()
    return order


def test_a_request_arriving_as_a_slot_frees_queues_behind_the_waiting_ones():
    assert asyncio.run(_order_of_service()) == ["first", "w1", "w2", "late"]
