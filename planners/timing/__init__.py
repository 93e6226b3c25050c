"""Timing methods: each reads ``PathConstraints`` and returns a ``TimeScaling``."""

from toptraj.planners.timing.base import TimeScaling, TimingMethod
from toptraj.planners.timing.jerk.method import JerkLimitedMethod
from toptraj.planners.timing.laws.method import ClassicalMethod, classical_methods
from toptraj.planners.timing.min_cost import MinCostMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.planners.timing.ruckig_method import RuckigMethod
from toptraj.planners.timing.toppra_method import ToppraMethod

#: ``timing.method`` name -> method.
METHODS: dict[str, TimingMethod] = {
    method.name: method for method in (PhasePlaneMethod(), ToppraMethod(), *classical_methods(), RuckigMethod(), MinCostMethod(), JerkLimitedMethod())
}

__all__ = ["METHODS", "ClassicalMethod", "PhasePlaneMethod", "TimeScaling", "TimingMethod", "ToppraMethod"]
