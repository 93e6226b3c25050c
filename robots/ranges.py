"""The accepted range of each kind of joint limit (SI units), one for every source of a limit:
a request's overrides (``timing.limits``), an upload's ``joint_limits.yaml``, a URDF's
``<limit>`` and the service's own table (``data/limits.toml``).

==============  =================  ==================================
limit           accepted range     unit (revolute; prismatic)
==============  =================  ==================================
velocity        [1e-6, 1e3]        rad/s; m/s
acceleration    [1e-6, 1e5]        rad/s^2; m/s^2
jerk            [1e-6, 1e8]        rad/s^3; m/s^3
torque          [1e-6, 1e5]        N m; N
==============  =================  ==================================

Every real arm lies well inside (the catalog's limits span 0.6 to 1e3 rad/s, 3 to 5e3 rad/s^2,
60 to 1e5 rad/s^3 and 3 to 1e3 N m), and the timing methods (phase_plane, toppra, min_cost,
ruckig, jerk_limited) answer at both ends of each range with a trajectory or a 4xx that says
why; outside, a limit such as 1e-300 rad/s^2 or 5e-324 rad/s^3 is positive in name only and
made ruckig fail, min_cost run out of time and toppra take seconds. ``inf`` (no limit) is the
one value outside a range that a robot may hold, and only where no file gave a number (the
papers' bundled arms).
"""

from __future__ import annotations

import math
from typing import NamedTuple


class Range(NamedTuple):
    """Closed interval [low, high] of a quantity, with its unit for messages."""

    low: float
    high: float
    unit: str

    def describe(self) -> str:
        """``[low, high] unit`` as a message shows it."""
        return f"[{self.low:g}, {self.high:g}]{' ' + self.unit if self.unit else ''}"

    def holds(self, value: float) -> bool:
        """Whether ``value`` lies in the range (NaN never does)."""
        return self.low <= value <= self.high

    def holds_signed(self, value: float) -> bool:
        """Whether ``value`` lies in [-high, high] (NaN never does)."""
        return -self.high <= value <= self.high


VELOCITY = Range(1e-6, 1e3, "rad/s")
ACCELERATION = Range(1e-6, 1e5, "rad/s^2")
JERK = Range(1e-6, 1e8, "rad/s^3")
TORQUE = Range(1e-6, 1e5, "N m")
#: The range of each limit kind, keyed as ``JointLimits`` names them.
LIMITS = {"velocity": VELOCITY, "acceleration": ACCELERATION, "jerk": JERK, "torque": TORQUE}


def limit_problem(kind: str, value: float, joint: str, source: str) -> str | None:
    """``None`` when ``value`` is an acceptable ``kind`` limit, else a sentence naming the joint,
    the limit, its value, its source and the accepted range (``inf``, no limit, is accepted)."""
    accepted = LIMITS[kind]
    if value == math.inf or accepted.holds(value):
        return None
    return (
        f"joint {joint!r}: the {kind} limit {value:g} {accepted.unit} from {source} is outside the accepted range "
        f"{accepted.describe()}"
    )


#: What a robot carries and how it is mounted (``toptraj.robots.equipment``): one range per quantity.
#: A payload's mass: none to a heavy-duty arm's rated load.
PAYLOAD_MASS = Range(0.0, 1e3, "kg")
#: Each coordinate of a payload's centre of mass in its frame (signed): a tool is within a few metres.
CENTER_OF_MASS = Range(0.0, 10.0, "m")
#: Radius of a payload's collision sphere about its centre of mass (0: not a collision body).
PAYLOAD_RADIUS = Range(0.0, 2.0, "m")
#: Each entry of a payload's rotational inertia about its centre of mass (principal moments in
#: [0, high], products of inertia in [-high, high]): a 1,000 kg box 3 m wide holds 1.5e3 kg m^2.
PAYLOAD_INERTIA = Range(0.0, 1e4, "kg m^2")
#: Each coordinate of a robot's base in the world (signed).
BASE_POSITION = Range(0.0, 1e3, "m")
#: Each component of the gravity vector in the world (signed): 0 (space) to 10 g.
GRAVITY = Range(0.0, 100.0, "m/s^2")
