"""Start-up, import cost and memory of the service and the command line, against one bare toppra
solve of the typical request (``anchors.bare_toppra``, ``end_to_end.py``) measured in the same
run, interleaved: each round times the anchor (the median of ``--solves`` solves), then
``toptraj plan`` of the typical request (a new interpreter: what a user waits for), then, every
``--restart-every`` rounds, a restart of ``toptraj serve --workers 1`` (numba's cache warm) until
``/health`` answers.

Printed beside each goal of the issue:

* ``toptraj plan`` of the typical request <= 100x, beside two floors: a new interpreter that
  imports numpy, Pinocchio and pydantic (what any plan imports), and the same calling one kernel
  from numba's cache (numba's own start, which a plan pays when a kernel it calls is not in the
  install's ahead-of-time library, ``toptraj.compiled``);
* a restart ready within 3 s (<= 600x), the longest silence of its log before ``/health``;
* each server process <= 300 MB resident at idle, with its fork server's (which preloads the
  stacks of its children: ``toptraj.planners.execution.isolated.PRELOAD``);
* with ``--fresh``: the install's step (``python -m toptraj.service.warmup`` into an empty numba cache,
  as after a fresh clone) and then the first start ready within 15 s (<= 3,000x), with the
  longest silence of either.

Then the CPU seconds (user and system) of the same, against the bare solve's: on a busy
machine the wall seconds of a new interpreter vary twofold between rounds, its CPU seconds by a
few percent. Each tree's bytecode is written first, as the install writes it.

With ``--baseline DIR`` (another checkout, e.g. ``git archive main | tar -x -C DIR``, its
kernels compiled once), the same ``toptraj plan`` and restart of that tree, interleaved.

    python benchmarks/startup.py [--rounds 5] [--restart-every 1] [--fresh] [--baseline DIR]
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import resource
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import psutil

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from anchors import bare_toppra  # noqa: E402

from toptraj import robots  # noqa: E402
from toptraj.service.warmup import TYPICAL  # noqa: E402


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _env(root: Path) -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")]))}


#: The floor's kernel: one cached numba function, in a module of its own.
_FLOOR_KERNEL = """
import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def kernel(x):
    return np.sqrt(x) + 1.0
"""


def _children_cpu() -> float:
    """CPU seconds (user and system) of this process's ended children so far."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def _floor(folder: str, numba: bool = True) -> tuple[float, float]:
    """Wall and CPU seconds of a new interpreter importing numpy, Pinocchio and pydantic and,
    with ``numba``, calling one cached numba kernel (``_FLOOR_KERNEL`` in ``folder``)."""
    started, cpu = time.perf_counter(), _children_cpu()
    kernel = "import floor_kernel; floor_kernel.kernel(numpy.ones(3))" if numba else ""
    subprocess.run([sys.executable, "-c", f"import numpy, pinocchio, pydantic; {kernel}"], cwd=folder, check=True)
    return time.perf_counter() - started, _children_cpu() - cpu


def _bytecode(root: Path) -> None:
    """The bytecode of the tree at ``root`` written, as an install writes it (pip; ``make
    install``'s warm-up), even where ``PYTHONDONTWRITEBYTECODE`` keeps Python from writing it on
    import: otherwise each new interpreter would compile the project's sources again."""
    folders = [str(root / part) for part in ("toptraj", "robots", "planners", "service", "client", "compiled")]
    subprocess.run([sys.executable, "-m", "compileall", "-q", *folders], check=True, stdout=subprocess.DEVNULL)


def _cli_plan(request_file: str, env: dict, root: Path = ROOT) -> tuple[float, float]:
    """Wall and CPU seconds of ``toptraj plan FILE`` (a new interpreter), its answer checked."""
    started, cpu = time.perf_counter(), _children_cpu()
    done = subprocess.run([sys.executable, "-m", "toptraj.service.cli", "plan", request_file], cwd=root, env=env, capture_output=True)
    seconds = time.perf_counter() - started, _children_cpu() - cpu
    if done.returncode != 0 or not done.stdout.startswith(b'{"robot":"ur5"'):
        raise RuntimeError(f"toptraj plan failed: {done.stderr[-500:]!r}")
    return seconds


class _Server:
    """``toptraj serve --workers 1`` on a free port: seconds until ``/health`` answers, the
    longest gap between two lines of its log until then, and the resident memory at idle."""

    def __init__(self, env: dict, root: Path = ROOT):
        self.port = _free_port()
        self.lines: list[tuple[float, str]] = []
        self.started = time.perf_counter()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(self.port), "--workers", "1"],
            cwd=root, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        )
        threading.Thread(target=self._read, daemon=True).start()
        self.ready_s = self._wait_ready()
        used = psutil.Process(self.process.pid).cpu_times()
        self.ready_cpu_s = used.user + used.system

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.append((time.perf_counter(), line.rstrip()))

    def _wait_ready(self) -> float:
        give_up = time.monotonic() + 600
        while time.monotonic() < give_up:
            if self.process.poll() is not None:
                raise RuntimeError(f"the server exited: {self.lines[-5:]}")
            try:
                connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=2)
                connection.request("GET", "/health")
                if connection.getresponse().status == 200:
                    return time.perf_counter() - self.started
            except OSError:
                pass
            time.sleep(0.05)
        raise RuntimeError("the server did not answer /health within 600 s")

    def longest_silence(self) -> float:
        """Longest gap in s between the start, its log lines and ``/health`` answering."""
        ready = self.started + self.ready_s
        times = [self.started, *(t for t, _ in self.lines if t <= ready), ready]
        return float(np.max(np.diff(times)))

    def idle_rss_mb(self, settle_s: float = 20.0) -> tuple[float, float]:
        """(server process, its fork server) resident MB once the fork server has finished its
        preload (its CPU time stops growing) and both are idle."""
        server = psutil.Process(self.process.pid)
        give_up = time.monotonic() + settle_s
        fork_server, last_cpu = None, -1.0
        while time.monotonic() < give_up:
            children = [c for c in server.children() if "forkserver" in " ".join(c.cmdline())]
            if children:
                fork_server = children[0]
                cpu = sum(fork_server.cpu_times()[:2])
                if cpu == last_cpu:
                    break
                last_cpu = cpu
            time.sleep(1.0)
        fork_mb = fork_server.memory_info().rss / 2**20 if fork_server is not None else float("nan")
        return server.memory_info().rss / 2**20, fork_mb

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def _anchor(robot, waypoints, solves: int) -> tuple[float, float]:
    """Median wall and CPU seconds of ``solves`` bare toppra solves."""
    timed = [_timed(lambda: bare_toppra(robot, waypoints)) for _ in range(solves)]
    return float(np.median([wall for wall, _ in timed])), float(np.median([cpu for _, cpu in timed]))


def _timed(function) -> tuple[float, float]:
    started, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - started, time.process_time() - cpu


def _goal(label: str, value: float, goal: float, unit: str = "x") -> None:
    print(f"  {label:44s} {value:9.1f}{unit:3s} goal <= {goal:g}{unit}   {'met' if value <= goal else 'MISSED'}")


def _fresh(anchor_s: float) -> None:
    """The install's warm-up into an empty numba cache, then the first start on it."""
    with tempfile.TemporaryDirectory(prefix="toptraj-numba-") as cache:
        env = {**_env(ROOT), "NUMBA_CACHE_DIR": cache}
        started = time.perf_counter()
        install = subprocess.Popen([sys.executable, "-m", "toptraj.service.warmup"], cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True)
        assert install.stdout is not None
        stamps = [started]
        for line in install.stdout:
            stamps.append(time.perf_counter())
            print(f"    {stamps[-1] - started:6.1f} s  {line.rstrip()}")
        install.wait()
        install_s = time.perf_counter() - started
        print(f"  install step (python -m toptraj.service.warmup, empty cache): {install_s:.1f} s, "
              f"longest silence {np.max(np.diff(stamps)):.1f} s")
        server = _Server(env)
        try:
            _goal("first start after the install / bare toppra", server.ready_s / anchor_s, 3000)
            print(f"  {'':44s} ({server.ready_s:.2f} s; longest silence {server.longest_silence():.2f} s)")
        finally:
            server.stop()


def _report(trees, anchors, floors, bare_floors, plans, restarts, silences, memory, rounds: int) -> float:
    """Print the medians and the goals (wall seconds), then the same in CPU seconds (less
    sensitive to a busy machine than wall seconds); the anchor's median wall seconds."""
    anchor, anchor_cpu = (float(np.median([a[k] for a in anchors])) for k in (0, 1))
    wall = {key: [float(np.median([m[0] for m in values[name]])) for name in trees] for key, values in (("plan", plans), ("restart", restarts))}
    print(f"typical request (ur5, 4 spline waypoints, velocity + acceleration + torque, phase_plane, dt 0.01); "
          f"{rounds} interleaved rounds; bare toppra {1e3 * anchor:.2f} ms (median)")
    for label, values in (("", bare_floors), (", one cached numba kernel", floors)):
        floor = float(np.median([f[0] for f in values]))
        print(f"  floor (interpreter, numpy, pinocchio, pydantic{label}): {floor:.3f} s median, {floor / anchor:.1f}x bare toppra")
    for k, (name, root) in enumerate(trees.items()):
        print(f"{name} ({root}):")
        print(f"  toptraj plan: {wall['plan'][k]:.3f} s median ({', '.join(f'{s:.2f}' for s, _ in plans[name])})")
        print(f"  restart to /health: {wall['restart'][k]:.2f} s median ({', '.join(f'{s:.2f}' for s, _ in restarts[name])}); "
              f"longest silence {max(silences[name]):.2f} s")
        _goal("toptraj plan / bare toppra", wall["plan"][k] / anchor, 100)
        _goal("restart ready / bare toppra", wall["restart"][k] / anchor, 600)
        server_mb, fork_mb = memory[name]
        _goal("server process resident at idle", server_mb, 300, " MB")
        print(f"  {'its fork server (children share its pages)':44s} {fork_mb:9.1f} MB")
    bare, numba = (float(np.median([f[1] for f in values])) for values in (bare_floors, floors))
    print(f"CPU seconds (user + system), medians: bare toppra {1e3 * anchor_cpu:.2f} ms; floors {bare:.3f} s "
          f"({bare / anchor_cpu:.1f}x) and with numba {numba:.3f} s ({numba / anchor_cpu:.1f}x)")
    for name in trees:
        plan_cpu, restart_cpu = (float(np.median([m[1] for m in values[name]])) for values in (plans, restarts))
        print(f"  {name}: toptraj plan {plan_cpu:.3f} s ({plan_cpu / anchor_cpu:.1f}x bare toppra); "
              f"server process until ready {restart_cpu:.2f} s ({restart_cpu / anchor_cpu:.1f}x)")
    return anchor


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--solves", type=int, default=20, help="bare toppra solves per anchor (their median)")
    parser.add_argument("--restart-every", type=int, default=1, help="a server restart every this many rounds")
    parser.add_argument("--fresh", action="store_true", help="also the install step into an empty cache and the first start")
    parser.add_argument("--baseline", type=Path, default=None, help="another checkout timed alike, interleaved")
    args = parser.parse_args()
    trees = {"this tree": ROOT, **({"baseline": args.baseline.resolve()} if args.baseline else {})}

    import toppra

    toppra.setup_logging("WARNING")
    robot = robots.load("ur5")
    waypoints = np.array(TYPICAL["path"]["waypoints"])
    for _ in range(5):
        bare_toppra(robot, waypoints)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as handle:
        json.dump(TYPICAL, handle)
    for root in trees.values():
        _bytecode(root)
        _cli_plan(handle.name, _env(root), root)  # numba's cache written, if it was not
    floor_folder = tempfile.mkdtemp(prefix="toptraj-floor-")
    Path(floor_folder, "floor_kernel.py").write_text(_FLOOR_KERNEL)
    _floor(floor_folder)  # compiled into its cache
    floors: list[tuple[float, float]] = []
    bare_floors: list[tuple[float, float]] = []
    anchors: list[tuple[float, float]] = []
    plans: dict[str, list[tuple[float, float]]] = {name: [] for name in trees}
    restarts: dict[str, list[tuple[float, float]]] = {name: [] for name in trees}
    silences: dict[str, list[float]] = {name: [] for name in trees}
    memory: dict[str, tuple[float, float]] = {}
    try:
        for round_ in range(args.rounds):
            anchors.append(_anchor(robot, waypoints, args.solves))
            floors.append(_floor(floor_folder))
            bare_floors.append(_floor(floor_folder, numba=False))
            for name, root in trees.items():
                plans[name].append(_cli_plan(handle.name, _env(root), root))
                if round_ % args.restart_every == 0:
                    server = _Server(_env(root), root)
                    try:
                        restarts[name].append((server.ready_s, server.ready_cpu_s))
                        silences[name].append(server.longest_silence())
                        if name not in memory:
                            memory[name] = server.idle_rss_mb()
                    finally:
                        server.stop()
    finally:
        os.unlink(handle.name)
        shutil.rmtree(floor_folder, ignore_errors=True)
    anchor = _report(trees, anchors, floors, bare_floors, plans, restarts, silences, memory, args.rounds)
    if args.fresh:
        _fresh(anchor)
    return 0


if __name__ == "__main__":
    sys.exit(main())
