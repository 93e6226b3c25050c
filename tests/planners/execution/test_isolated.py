"""``toptraj.planners.execution.isolated``: a function run in a worker process returns its result or raises its
error, and is killed when the deadline passes or is cancelled."""

from __future__ import annotations

import os
import pickle
import threading
import time

import numpy as np
import psutil
import pytest

from toptraj import robots
from toptraj.planners import BudgetExceeded, Deadline, InfeasiblePath
from toptraj.planners.errors import OverMemory
from toptraj.planners.execution.isolated import run_isolated


def _spin(pid_file: str) -> None:
    with open(pid_file, "w") as handle:
        handle.write(f"{os.getpid()} {psutil.Process().create_time()}")
    while True:
        pass


def _fail() -> None:
    raise InfeasiblePath("no way through", s=0.25, joint="elbow")


def _torques(robot: robots.Robot, q: np.ndarray) -> np.ndarray:
    return robot.inverse_dynamics(q, np.ones_like(q), np.ones_like(q))


def test_the_result_comes_back_from_the_worker_process():
    robot = robots.load("ur5")
    q = np.linspace(-1.0, 1.0, 12).reshape(2, 6)
    np.testing.assert_array_equal(run_isolated(_torques, robot, q, deadline=Deadline(60)), _torques(robot, q))
    assert run_isolated(os.getpid, deadline=Deadline(60)) != os.getpid()


def test_an_error_comes_back_with_its_facts():
    with pytest.raises(InfeasiblePath) as caught:
        run_isolated(_fail, deadline=Deadline(60))
    assert (caught.value.detail, caught.value.s, caught.value.joint) == ("no way through", 0.25, "elbow")


def _killed(pid_file) -> bool:
    """Whether the worker that wrote ``pid_file`` is gone (its number may already belong to
    another process on a busy machine: the start time tells them apart)."""
    pid, created = pid_file.read_text().split()
    try:
        process = psutil.Process(int(pid))
        return process.create_time() != float(created) or process.status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


def test_the_worker_is_killed_when_the_deadline_passes(tmp_path):
    pid_file = tmp_path / "pid"
    with pytest.raises(BudgetExceeded):
        # long enough for the worker to start spinning even on a busy machine
        run_isolated(_spin, str(pid_file), deadline=Deadline(3.0))
    assert _killed(pid_file)


def test_the_worker_is_killed_when_the_deadline_is_cancelled(tmp_path):
    pid_file = tmp_path / "pid"
    deadline = Deadline(600)

    def cancel_once_started():
        while not pid_file.exists() or not pid_file.read_text():
            time.sleep(0.01)
        deadline.cancel()

    threading.Thread(target=cancel_once_started, daemon=True).start()
    with pytest.raises(BudgetExceeded):
        run_isolated(_spin, str(pid_file), deadline=deadline)
    assert _killed(pid_file)


def test_cancelling_kills_the_worker_at_once_from_the_cancelling_thread(tmp_path, monkeypatch):
    """A 504 cancels the deadline from the event loop: the worker dies then, not when the thread
    waiting for it next polls (made 600 s here), so no work runs on after the answer."""
    import toptraj.planners.execution.isolated

    monkeypatch.setattr(toptraj.planners.execution.isolated, "POLL_S", 600.0)
    pid_file = tmp_path / "pid"
    deadline = Deadline(600)
    outcome: list[BaseException] = []

    def wait_for_worker():
        try:
            run_isolated(_spin, str(pid_file), deadline=deadline)
        except BaseException as error:  # noqa: BLE001 - examined below
            outcome.append(error)

    waiting = threading.Thread(target=wait_for_worker, daemon=True)
    waiting.start()
    while not pid_file.exists() or not pid_file.read_text():
        time.sleep(0.01)
    worker = psutil.Process(int(pid_file.read_text().split()[0]))
    spun = sum(worker.cpu_times()[:2])
    deadline.cancel()
    # Gone before it computed one CPU-second more (CPU time, not wall time: a busy machine slows
    # how soon the worker is reaped, not how much it spins); a kill left to the waiting thread's
    # next poll would let it spin for minutes.
    give_up = time.monotonic() + 60.0  # a hang guard
    while not _killed(pid_file):
        try:
            assert sum(worker.cpu_times()[:2]) - spun < 1.0, "the worker spins on after the cancel"
        except psutil.NoSuchProcess:
            break
        assert time.monotonic() < give_up
        time.sleep(0.01)
    waiting.join(60.0)
    assert len(outcome) == 1 and isinstance(outcome[0], BudgetExceeded), outcome


def test_a_robot_pickles_as_its_model():
    robot = robots.load("panda")
    copy = pickle.loads(pickle.dumps(robot))
    assert copy.model == robot.model and copy.joint_names == robot.joint_names
    q = np.full((1, robot.dof), 0.3)
    np.testing.assert_allclose(_torques(copy, q), _torques(robot, q), atol=1e-12)


def _blas_threads() -> int:
    import numpy  # noqa: F401  (its BLAS loaded)
    from threadpoolctl import threadpool_info

    return max(pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas")


@pytest.mark.skipif(os.cpu_count() < 2, reason="a one-core machine gives BLAS one thread anyway")
def test_the_worker_process_keeps_to_one_blas_thread():
    """A multi-threaded BLAS spins its threads: with the other core busy, the Geering
    collocation ran more than ten times slower than alone and over its budget."""
    assert run_isolated(_blas_threads, deadline=Deadline(60)) == 1


@pytest.mark.skipif(os.cpu_count() < 2, reason="a one-core machine gives BLAS one thread anyway")
def test_the_service_process_keeps_to_one_blas_thread():
    from toptraj.service.app import create_app
    from toptraj.service.settings import Settings

    create_app(Settings(preload_robots=False))
    assert _blas_threads() == 1


def _allocate(megabytes: int) -> int:
    block = np.ones(megabytes * 2**20 // 8)  # touched, so that it is really held
    return int(block.size)


def _priority() -> int:
    return os.getpriority(os.PRIO_PROCESS, 0)


def test_a_worker_over_its_memory_allowance_gets_a_clear_error_not_the_system_killing_it():
    with pytest.raises(OverMemory, match="memory allowance of 0.25 GiB"):
        run_isolated(_allocate, 1024, deadline=Deadline(60), memory_bytes=2**28)
    # within its allowance the same work is done, and the allowance is the worker's alone
    assert run_isolated(_allocate, 64, deadline=Deadline(60), memory_bytes=2**28) == 64 * 2**17
    assert _allocate(512) == 512 * 2**17


def test_a_worker_may_run_at_a_lower_cpu_priority():
    assert run_isolated(_priority, deadline=Deadline(60), nice=5) == min(_priority() + 5, 19)
    assert run_isolated(_priority, deadline=Deadline(60)) == _priority()


def _nested(megabytes: int) -> tuple[int, int]:
    """A call with a memory allowance made inside a worker process (inline), then the same
    allocation after it."""
    try:
        inside = run_isolated(_allocate, megabytes, deadline=Deadline(60), memory_bytes=2**28)
    except OverMemory:
        inside = -1
    return inside, _allocate(megabytes)


def test_a_call_inside_a_worker_process_keeps_its_memory_allowance_for_the_call():
    assert run_isolated(_nested, 512, deadline=Deadline(60)) == (-1, 512 * 2**17)
    assert run_isolated(_nested, 64, deadline=Deadline(60)) == (64 * 2**17, 64 * 2**17)


def _huge_pages() -> bool:
    return bool(np._core.multiarray._get_madvise_hugepage())


def test_workers_allocate_without_huge_pages_unless_asked():
    """A worker touches its large arrays once (``WORKER_HUGEPAGES``): numpy's huge pages are off
    there, whatever the calling process's numpy does."""
    if os.environ.get("NUMPY_MADVISE_HUGEPAGE", "0") != "0":
        pytest.skip("this environment asks for huge pages")
    assert run_isolated(_huge_pages, deadline=Deadline(60)) is False


def _kills_itself() -> None:
    import signal

    os.kill(os.getpid(), signal.SIGKILL)  # as the system kills a process for memory


def test_a_worker_killed_is_a_worker_stopped_not_a_refusal_of_the_request():
    """A worker that dies without an answer says so, with its exit code; the service answers it
    503 with the advice to submit again (a 422 said the request was at fault)."""
    from toptraj.planners.errors import WorkerStopped
    from toptraj.service.problems import detail, status_of

    with pytest.raises(WorkerStopped) as raised:
        run_isolated(_kills_itself, deadline=Deadline(30.0))
    assert raised.value.exit_code == -9
    assert status_of(raised.value) == 503
    assert detail(raised.value).startswith("the worker process computing this request stopped without an answer (exit code -9")
    assert "submit it again" in detail(raised.value)
