"""The initial guesses of the collocation (``toptraj.planners.generators.collocation.collocation``):
the goals a motion may end at (the goal itself and, for continuous joints, the goal one
revolution either way) and the bends added mid-way to the straight joint line towards each."""

from __future__ import annotations

import itertools

import numpy as np

from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.robots import Robot

#: Amplitude (rad or m) of the bends added to the straight line in the initial guesses.
BEND = 1.0


def goal_guesses(robot: Robot, motion: FreeMotion) -> list[tuple[str, np.ndarray]]:
    """The straight-line goal and, for continuous joints, the goal one revolution either way."""
    options = [("straight line", motion.goal)]
    continuous = np.flatnonzero(robot.continuous) if motion.revolutions else np.empty(0, dtype=int)
    for shifts in itertools.product((-2 * np.pi, 0.0, 2 * np.pi), repeat=len(continuous)):
        if not any(shifts):
            continue
        goal = motion.goal.copy()
        goal[continuous] += shifts
        label = ", ".join(f"{robot.joint_names[j]} {shift:+.4f} rad" for j, shift in zip(continuous, shifts) if shift)
        options.append((f"goal shifted: {label}", goal))
    return options


def bend_guesses(n_dof: int) -> list[tuple[str, np.ndarray]]:
    """Straight, and bent one joint at a time both ways (all joints together beyond three)."""
    options = [("", np.zeros(n_dof))]
    directions = np.eye(n_dof) if n_dof <= 3 else np.ones((1, n_dof))
    for direction in directions:
        for sign in (1.0, -1.0):
            joints = "all joints" if n_dof > 3 else f"joint {int(np.argmax(direction))}"
            options.append((f", bent {'+' if sign > 0 else '-'}{BEND:g} at {joints}", sign * BEND * direction))
    return options
