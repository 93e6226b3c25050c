"""Jeong & Lee's figure captions (section 4.3, Figs. 1 to 4) against the free-path answers'
switching times on the Geering arm, switch by switch.

    python benchmarks/switching_times.py

For each type: the caption's switching times of u1 and u2 and T, ours (the answer's
``switching_times``, from the bang-bang refinement, in the caption's orientation: a
time-reversed motion is as fast on this arm, ``toptraj.planners.generators.collocation.bang_bang.mirrored``), and
the differences in ms. Type 1 is solved with its structure (Type 2 without u1's last arc),
seeded by the Type 2 answer, as ``tests/planners/generators/test_switching_times.py`` does: at phi_b = 0.979 the
answer itself is Type 2. Then the switches read off the collocation's own instants (30
intervals), without the refinement, against the refined ones of Type 3.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from toptraj import robots  # noqa: E402
from toptraj.planners import LimitRequest, Sampling, build_problem, plan  # noqa: E402
from toptraj.planners.generators.collocation.bang_bang import BangBang, collocation_switches, mirrored  # noqa: E402
from toptraj.planners.generators.collocation.collocation import _optimize_motion  # noqa: E402
from toptraj.planners.generators.collocation.generator import Collocation
from toptraj.planners.generators.collocation.switching import refine_switching  # noqa: E402
from toptraj.planners.problem.free_motion import FreeMotion  # noqa: E402


def answer(arm, phi_b: float, revolutions: bool):
    motion = FreeMotion(np.zeros(2), np.array([phi_b, 0.0]), revolutions=revolutions)
    return plan(build_problem(arm, motion, Collocation(), limits=LimitRequest(kinds=("torque",)), sampling=Sampling(dt=0.002)))


def controls_of(answer, arm) -> BangBang:
    read = collocation_switches(answer.samples.t, answer.samples.tau, arm.limits.torque)
    switches = tuple(np.array(answer.switching_times.of(name)) for name in arm.joint_names)
    return BangBang(read.signs, switches, answer.duration)


def oriented(controls: BangBang, u1_first: int, u2_first: int) -> tuple[BangBang, bool]:
    """The controls in the caption's orientation, and whether they had to be mirrored."""
    if (controls.signs[0][0], controls.signs[1][0]) == (u1_first, u2_first):
        return controls, False
    return mirrored(controls), True


def row(label: str, caption_u1, caption_u2, caption_T: float, ours: BangBang, note: str) -> float:
    T = ours.duration
    expected = [np.array([T / 2 if v == "T/2" else v for v in caption]) for caption in (caption_u1, caption_u2)]
    print(f"{label}  ({note})   T: caption {caption_T:.4f} s, ours {T:.5f} s, {1e3 * (T - caption_T):+.2f} ms")
    worst = 0.0
    for joint, (caption, mine) in enumerate(zip(expected, ours.switches)):
        if len(caption) != len(mine):
            print(f"    u{joint + 1}: {len(mine)} switches against the caption's {len(caption)}")
            return np.inf
        differences = 1e3 * (mine - caption)
        worst = max(worst, float(np.abs(differences).max(initial=0.0)))
        print(
            f"    u{joint + 1}: caption " + ", ".join(f"{c:.4f}" for c in caption)
            + "   ours " + ", ".join(f"{m:.4f}" for m in mine)
            + "   difference (ms) " + ", ".join(f"{d:+.2f}" for d in differences)
        )
    return worst


def main() -> int:
    arm = robots.load("geering_2r")
    worst = []
    type_2 = answer(arm, 0.981, revolutions=False)
    two, flipped = oriented(controls_of(type_2, arm), 1, -1)
    worst.append(row("Type 2, phi_b 0.981, psi_b 0", [0.513, 1.056], [0.113, 0.634], 1.085, two,
                     "the answer, mirrored" if flipped else "the answer, as returned"))
    seed = BangBang((two.signs[0][:-1], two.signs[1]), (two.switches[0][:-1], two.switches[1]), two.duration)
    one = refine_switching(arm, arm.limits.torque, np.zeros(2), np.array([0.979, 0.0]), seed)
    at_0979 = answer(arm, 0.979, revolutions=False)
    worst.append(row("Type 1, phi_b 0.979, psi_b 0", [0.5425], [0.088, 0.588], 1.085, one.controls,
                     f"Type 1 structure; the answer at 0.979 is {controls_of(at_0979, arm).label()}, "
                     f"T {at_0979.duration:.5f} s"))
    type_3 = answer(arm, 0.76, revolutions=True)
    three = controls_of(type_3, arm)
    worst.append(row("Type 3, phi_b 0.76, psi_b -2 pi", [0.190, "T/2", 0.785], ["T/2"], 0.9755, three,
                     "the answer, its own mirror image"))
    type_4 = answer(arm, np.pi, revolutions=True)
    worst.append(row("Type 4, phi_b pi, psi_b -2 pi", ["T/2"], [0.278, "T/2", 0.974], 1.252, controls_of(type_4, arm),
                     "the answer, its own mirror image"))
    print(f"\nlargest difference from a caption's switching time: {max(worst):.2f} ms (goal: 5 ms)")

    motion = FreeMotion(np.zeros(2), np.array([0.76, -2 * np.pi]), revolutions=False, intervals=30)
    collocation = _optimize_motion(arm, arm.limits, motion, 0.0, 1000)
    read = collocation_switches(collocation.t, collocation.tau, arm.limits.torque)
    errors = 1e3 * np.abs(np.concatenate(read.switches) - np.concatenate(three.switches))
    print(f"collocation alone (30 intervals, h = {1e3 * collocation.t[1]:.1f} ms), Type 3: switches "
          f"{', '.join(f'{e:.2f}' for e in errors)} ms from the refined ones")
    return 0


if __name__ == "__main__":
    sys.exit(main())
