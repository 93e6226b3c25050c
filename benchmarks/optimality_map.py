"""Jeong & Lee's optimality map (section 4.3) of the Geering arm: which family of time-optimal
motions wins as the shoulder goal phi_b grows, with the elbow free (back to 0 or a full turn).

    python benchmarks/optimality_map.py --step 0.1 --width 1e-3

Discovers the families from the free-path answers at a few anchor goals
(``toptraj.planners.generators.collocation.optimality_map``), prints one row per phi_b (each family's T in s, "-"
where it does not exist, and the winner), then the boundaries between winners by bisection.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from toptraj import robots
from toptraj.planners.generators.collocation.optimality_map import boundary, discover, key, sweep

#: The paper's names of the switching structures (u1; u2) for each elbow goal.
PAPER_TYPES = {
    (0.0, "(max, min); (min, max, min)"): "Type 1",
    (0.0, "(max, min, max); (min, max, min)"): "Type 2",
    (-2 * np.pi, "(max, min, max, min); (min, max)"): "Type 3",
    (-2 * np.pi, "(max, min); (min, max, min, max)"): "Type 4",
}


def paper_type(family) -> str:
    for (elbow, label), name in PAPER_TYPES.items():
        if abs(family.elbow - elbow) < 1e-9 and family.label == label:
            return name
    return key(family)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--anchors", default="0.5,0.98,1.25,2.5", help="shoulder goals (rad) of the free-path answers")
    parser.add_argument("--step", type=float, default=0.1, help="sweep step of phi_b (rad)")
    parser.add_argument("--width", type=float, default=1e-3, help="bisection bracket width (rad)")
    args = parser.parse_args()
    arm = robots.load("geering_2r")
    started = time.perf_counter()
    families = discover(arm, [float(a) for a in args.anchors.split(",")])
    print(f"families from the free-path answers ({time.perf_counter() - started:.1f} s):")
    for family in families:
        print(f"  {paper_type(family)}: psi_b = {family.elbow:+.4f} rad, u1; u2 = {family.label}")
    phis = np.round(np.arange(args.step, np.pi + 1e-9, args.step), 6)
    if phis[-1] < np.pi - 1e-9:
        phis = np.append(phis, np.pi)
    rows = sweep(families, phis)
    names = [paper_type(f) for f in families]
    print("\nphi_b (rad) | " + " | ".join(f"{n:>8}" for n in names) + " | fastest")
    for phi, durations, best in rows:
        cells = [("-" if durations[key(f)] is None else f"{durations[key(f)]:.5f}") for f in families]
        winner = next(paper_type(f) for f in families if key(f) == best) if best else "-"
        print(f"{phi:11.4f} | " + " | ".join(f"{c:>8}" for c in cells) + f" | {winner}")
    print("\nboundaries (bisection):")
    for (phi_a, _, best_a), (phi_b, _, best_b) in zip(rows[:-1], rows[1:]):
        if best_a != best_b and best_a is not None and best_b is not None:
            below = next(f for f in families if key(f) == best_a)
            above = next(f for f in families if key(f) == best_b)
            lower, upper = boundary(families, below, phi_a, phi_b, args.width)
            print(f"  {paper_type(below)} -> {paper_type(above)}: phi_b in [{lower:.5f}, {upper:.5f}] rad")
    print(f"\ntotal {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
