"""Several arms in one workspace, each along its own given path, timed together so that they
keep a clearance from each other (path-velocity decomposition, Kant & Zucker 1986; the
coordination diagram of O'Donnell & Lozano-Pérez 1989): ``cell`` (the arms and their poses),
``diagram`` (the collision region in (s1, s2)), ``curve`` (the quickest monotone curve),
``timing`` (each arm's optimum and the pair along a curve), ``verify`` (fine checks) and
``coordinate`` (the whole)."""

from toptraj.planners.coordination.cell import Cell, CellArm
from toptraj.planners.coordination.coordinate import Coordination, coordinate

__all__ = ["Cell", "CellArm", "Coordination", "coordinate"]
