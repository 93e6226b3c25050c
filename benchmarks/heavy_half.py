"""Light requests beside heavy ones: a 2-process server under two ur5 global searches that run past
their budget, with two streams of the typical request alongside.

    python benchmarks/heavy_half.py [--budget 3] [--rounds 1]

Prints, per round: the searches' statuses and when their 504s came, the typical request's
latency alone and under the searches (p50, p99, max) with its statuses, the server's process
tree CPU time in the 2 s after both 504s, and its resident memory warm, at its peak during the
searches and when it came back within 200 MB of the warm figure. The targets (issue "Trust for
the heavy half"): p99 under 1 s, under 0.5 CPU-s, back within 200 MB within 5 s;
``tests/service/test_heavy_admission.py`` asserts them once.
"""

from __future__ import annotations

import argparse
import threading
import time

import numpy as np

from tests.live_server import LiveServer
from tests.test_heavy_admission import SEARCH, TYPICAL, _tree_rss


def one_round(budget_s: float) -> None:
    with LiveServer(workers=2, TOPTRAJ_PLAN_BUDGET_S=str(budget_s)) as server:
        server.wait_until_idle()
        for _ in range(20):  # both processes warm
            server.request("POST", "/v1/trajectories", TYPICAL)
        server.wait_until_idle()
        warm = _tree_rss(server)
        alone = []
        for _ in range(50):
            began = time.monotonic()
            server.request("POST", "/v1/trajectories", TYPICAL)
            alone.append(time.monotonic() - began)
        statuses: list[int] = []
        ended: list[float] = []
        latencies: list[float] = []
        codes: list[int] = []
        done = threading.Event()
        started = time.monotonic()

        def search() -> None:
            statuses.append(server.request("POST", "/v1/trajectories", SEARCH)[0])
            ended.append(time.monotonic())

        def stream() -> None:
            while not done.is_set():
                began = time.monotonic()
                codes.append(server.request("POST", "/v1/trajectories", TYPICAL)[0])
                latencies.append(time.monotonic() - began)
                time.sleep(0.02)

        threads = [threading.Thread(target=stream) for _ in range(2)] + [threading.Thread(target=search) for _ in range(2)]
        for thread in threads:
            thread.start()
        peak = 0
        while len(ended) < 2:
            peak = max(peak, _tree_rss(server))
            time.sleep(0.1)
        done.set()
        for thread in threads:
            thread.join()
        before = server.cpu_seconds()
        time.sleep(max(0.0, max(ended) + 2.0 - time.monotonic()))
        cpu = server.cpu_seconds() - before
        back = None
        while time.monotonic() < max(ended) + 5.0:
            if back is None and _tree_rss(server) - warm < 200e6:
                back = time.monotonic() - max(ended)
            time.sleep(0.1)

        def ms(values, q):
            return f"{1e3 * float(np.percentile(values, q)):.1f} ms"

        print(f"searches: {statuses}, answered {[round(t - started, 2) for t in ended]} s after they were sent (budget {budget_s:g} s)")
        print(f"typical request alone: p50 {ms(alone, 50)}, p99 {ms(alone, 99)}")
        print(
            f"typical request beside the searches: {len(latencies)} requests, p50 {ms(latencies, 50)}, p99 {ms(latencies, 99)}, "
            f"max {1e3 * max(latencies):.1f} ms, statuses {dict(sorted((c, codes.count(c)) for c in set(codes)))}"
        )
        print(f"process tree CPU in the 2 s after both 504s: {cpu:.3f} CPU-s")
        within = "not within 5 s" if back is None else f"{back:.1f} s after the last 504"
        print(f"resident memory: warm {warm / 1e6:.0f} MB, peak {peak / 1e6:.0f} MB, back within 200 MB of warm {within}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=float, default=3.0, help="the server's request budget, s")
    parser.add_argument("--rounds", type=int, default=1)
    args = parser.parse_args()
    for _ in range(args.rounds):
        one_round(args.budget)


if __name__ == "__main__":
    main()
