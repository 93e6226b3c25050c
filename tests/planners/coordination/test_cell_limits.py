"""Each arm of a cell held by its own torque limits, its payload and base pose included: the
torques of the timed pair on a dense resampling by an independent Pinocchio RNEA (the payload as
a link of the URDF, the base pose as the gravity the base feels), a torque limit that binds and
lengthens the motion, one that no timing holds, and an arm's own path that folds onto itself."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.planners.collision.test_self_collision import FOLDING
from tests.planners.coordination.cells import FIRST, SECOND, TURNED, facing_cell, ur5_arm
from tests.robots.test_equipment import COM, INERTIA, MASS, _ur5_with_load_link
from toptraj.planners.collision.self_collision import SelfCollision
from toptraj.planners.coordination import Cell, coordinate
from toptraj.planners.coordination.cell import CellArm
from toptraj.planners.errors import InfeasiblePath
from toptraj.robots.catalog import example_urdf_path
from toptraj.robots.equipment import payload

KINDS = ("velocity", "acceleration", "torque")
#: A 4 kg tool 0.1 m out along the tool's z axis.
TOOL = payload(4.0, (0.0, 0.0, 0.1))


def _reduced(arm: CellArm) -> CellArm:
    """``arm`` with its torque limits at 0.6 (90 N m on ur5's big joints)."""
    return CellArm(arm.robot, arm.path, arm.limits.with_request(scales={"torque": 0.6}))


def _cell(first_payload=None, kinds=KINDS) -> Cell:
    first = _reduced(ur5_arm(FIRST, [0.0, 0.0, 0.0], payload=first_payload))
    return Cell((first, _reduced(ur5_arm(SECOND, [1.2, 0.0, 0.0], TURNED))), 0.02, kinds)


def _rnea(model: pin.Model, q, qd, qdd) -> np.ndarray:
    data = model.createData()
    return np.array([pin.rnea(model, data, *state) for state in zip(q, qd, qdd)])


@pytest.fixture(scope="module")
def loaded():
    cell = _cell(payload(MASS, COM, [INERTIA[0, 0], INERTIA[1, 1], INERTIA[2, 2], INERTIA[0, 1], INERTIA[0, 2], INERTIA[1, 2]]))
    return cell, coordinate(cell)


def test_torques_on_a_dense_resampling_hold_by_an_independent_rnea(loaded):
    cell, found = loaded
    schedule = found.schedule
    t = np.linspace(0.0, schedule.duration, 8_001)
    references = (_ur5_with_load_link(), pin.buildModelFromUrdf(example_urdf_path("ur5")))
    for arm, reference, (q, qd, qdd) in zip(cell.arms, references, schedule.states(cell, t)):
        tau = _rnea(reference, q, qd, qdd)
        assert np.abs(arm.robot.inverse_dynamics(q, qd, qdd) - tau).max() <= 1e-9
        assert (np.abs(tau) <= arm.limits.torque * 1.005).all()
        assert (np.abs(qd) <= arm.limits.velocity * 1.005).all()
        assert (np.abs(qdd) <= arm.limits.acceleration * 1.005).all()


def test_a_ceiling_arms_torques_follow_the_gravity_its_base_feels():
    # hung from the ceiling (half a turn about x), the arm feels gravity reversed in its own frame
    ceiling = ur5_arm(FIRST, [0.0, 0.0, 2.0], np.diag([1.0, -1.0, -1.0]))
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-2.0, 2.0, (20, 6)) for _ in range(3))
    reversed_gravity = pin.buildModelFromUrdf(example_urdf_path("ur5"))
    reversed_gravity.gravity = pin.Motion(np.array([0.0, 0.0, 9.81]), np.zeros(3))
    assert np.abs(ceiling.robot.inverse_dynamics(q, qd, qdd) - _rnea(reversed_gravity, q, qd, qdd)).max() <= 1e-9


def test_a_payload_that_makes_a_torque_limit_bind_lengthens_the_cell():
    bare = coordinate(_cell())
    heavy = _cell(TOOL)
    found = coordinate(heavy)
    # the payload's arm alone takes longer, and its torque binds on a dense resampling of the pair
    assert found.solo[0] > 1.05 * bare.solo[0]
    assert found.solo[1] == pytest.approx(bare.solo[1], rel=1e-9)
    schedule = found.schedule
    t = np.linspace(0.0, schedule.duration, 20_001)
    q, qd, qdd = schedule.states(heavy, t)[0]
    peak = float((np.abs(heavy.arms[0].robot.inverse_dynamics(q, qd, qdd)) / heavy.arms[0].limits.torque).max())
    assert 0.98 <= peak <= 1.005
    without = _cell(TOOL, kinds=("velocity", "acceleration"))
    assert coordinate(without).solo[0] < found.solo[0]


def test_a_payload_no_timing_can_hold_is_refused_naming_the_arm_joint_and_s():
    cell = _cell(payload(40.0, (0.0, 0.0, 0.1)))
    with pytest.raises(InfeasiblePath, match=r"arms\[0\] \(ur5\)") as refused:
        coordinate(cell)
    assert "on joint 'shoulder_lift_joint'" in str(refused.value) and refused.value.s is not None
    assert (refused.value.joint, refused.value.limit) == ("shoulder_lift_joint", "torque")


def test_an_arm_whose_own_path_folds_onto_itself_is_refused_naming_the_links_and_s():
    cell = facing_cell()
    folding = ur5_arm(FOLDING, [0.0, 3.0, 0.0])
    with pytest.raises(
        SelfCollision, match=r"^arms\[1\] \(ur5\): links 'shoulder_link' and 'forearm_link' touch at s = "
    ) as refused:
        coordinate(Cell((cell.arms[0], folding), cell.clearance))
    assert {refused.value.link_a, refused.value.link_b} == {"shoulder_link", "forearm_link"} and 0.0 < refused.value.s < 1.0


def test_an_arm_the_gate_cannot_refine_within_its_tolerance_is_timed_on_its_grid(monkeypatch):
    """The limit gate gives up (``LimitExceeded``) after its rounds of refinement: the arm's grid
    timing is kept and the cell answered, its clock slowed where a limit needs it (the cell was
    refused with advice, another method or more grid points, that a cell cannot take)."""
    from toptraj.planners.checks import gate
    from toptraj.planners.errors import LimitExceeded

    def gives_up(*args, **kwargs):
        raise LimitExceeded("the toppra timing exceeds the torque limit of joint 'elbow_joint' by 1 % at s = 0.5")

    monkeypatch.setattr(gate, "gated", gives_up)
    found = coordinate(facing_cell(distance=3.0))
    assert found.schedule.duration > 0.0 and len(found.solo) == 2
