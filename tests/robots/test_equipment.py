"""A payload and a base pose written into a copy of the model (``toptraj.robots.equipment``),
against Pinocchio models built independently: the payload as a fixed link of the URDF, the
mounted arm as the floor arm under another gravity."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from toptraj import robots
from toptraj.robots import equipment
from toptraj.robots.catalog import example_urdf_path
from toptraj.robots.collision import robot_capsules

#: A 3 kg tool, its centre of mass off the flange's axis, with a full inertia (kg m^2).
MASS, COM = 3.0, (0.01, 0.02, 0.08)
INERTIA = np.array([[0.02, 0.001, -0.002], [0.001, 0.03, 0.0015], [-0.002, 0.0015, 0.025]])


def _ur5_with_load_link() -> pin.Model:
    """ur5 from its URDF with the payload as a link fixed to ``tool0`` (Pinocchio merges the
    link's inertia into the wrist joint's body when it reads the file)."""
    text = open(example_urdf_path("ur5")).read()
    i = INERTIA
    load = (
        f'<link name="load"><inertial><origin xyz="{COM[0]} {COM[1]} {COM[2]}" rpy="0 0 0"/><mass value="{MASS}"/>'
        f'<inertia ixx="{i[0, 0]}" iyy="{i[1, 1]}" izz="{i[2, 2]}" ixy="{i[0, 1]}" ixz="{i[0, 2]}" iyz="{i[1, 2]}"/>'
        '</inertial></link><joint name="load_joint" type="fixed"><parent link="tool0"/><child link="load"/></joint></robot>'
    )
    return pin.buildModelFromXML(text.replace("</robot>", load))


def _states(seed: int, n: int = 20):
    rng = np.random.default_rng(seed)
    return rng.uniform(-3.0, 3.0, (n, 6)), rng.uniform(-2.0, 2.0, (n, 6)), rng.uniform(-5.0, 5.0, (n, 6))


def test_payload_torques_equal_pinocchio_with_the_load_as_a_link():
    ur5 = robots.load("ur5")
    carrying = equipment.equip(ur5, equipment.payload(MASS, COM, [0.02, 0.03, 0.025, 0.001, -0.002, 0.0015]))
    reference = _ur5_with_load_link()
    data = reference.createData()
    q, qd, qdd = _states(1)
    expected = np.array([pin.rnea(reference, data, *state) for state in zip(q, qd, qdd)])
    assert np.abs(carrying.inverse_dynamics(q, qd, qdd) - expected).max() <= 1e-9
    assert np.abs(ur5.inverse_dynamics(q, qd, qdd) - expected).max() > 1.0  # the payload matters
    assert carrying.chain is not None  # the compiled pass, not Pinocchio's, gave the torques


def test_the_catalog_robot_is_never_changed_and_variants_are_cached():
    ur5 = robots.load("ur5")
    before = [pin.Inertia(inertia) for inertia in ur5.model.inertias]
    load = equipment.payload(5.0, (0.0, 0.0, 0.1))
    first = equipment.equip(ur5, load)
    assert equipment.equip(ur5, equipment.payload(5.0, (0.0, 0.0, 0.1))) is first
    assert equipment.equip(first, equipment.payload(0.0)) is ur5  # mass 0: none, back to the bare arm
    assert all(a.isApprox(b) for a, b in zip(before, ur5.model.inertias))
    assert ur5.payload is None and first.payload == load and first.bare is ur5


def test_ceiling_mounted_gravity_torques_are_the_floor_arms_with_gravity_reversed():
    ur5 = robots.load("ur5")
    ceiling = equipment.equip(ur5, mounting=equipment.mounting(position=(0.2, -0.1, 2.5), orientation=(1.0, 0.0, 0.0, 0.0)))
    reversed_gravity = ur5.model.copy()
    reversed_gravity.gravity = pin.Motion(np.array([0.0, 0.0, 9.81]), np.zeros(3))
    data = reversed_gravity.createData()
    q, _, _ = _states(2)
    rest = np.zeros_like(q)
    expected = np.array([pin.computeGeneralizedGravity(reversed_gravity, data, row) for row in q])
    assert np.abs(ceiling.inverse_dynamics(q, rest, rest) - expected).max() <= 1e-9
    assert np.abs(ur5.inverse_dynamics(q, rest, rest) + expected).max() <= 1e-9


def test_a_wall_mount_and_a_gravity_vector_give_the_gravity_the_base_feels():
    """Base turned by R in a world of gravity g: the arm feels R^T g."""
    ur5 = robots.load("ur5")
    rotation = pin.rpy.rpyToMatrix(0.3, -1.2, 0.7)
    gravity = np.array([0.5, -1.0, -3.7])
    mounted = equipment.equip(ur5, mounting=equipment.mounting(rotation=rotation, gravity=gravity))
    felt = ur5.model.copy()
    felt.gravity = pin.Motion(rotation.T @ gravity, np.zeros(3))
    data = felt.createData()
    q, qd, qdd = _states(3)
    expected = np.array([pin.rnea(felt, data, *state) for state in zip(q, qd, qdd)])
    assert np.abs(mounted.inverse_dynamics(q, qd, qdd) - expected).max() <= 1e-9


def test_mounting_places_the_arm_and_its_base_capsules_in_the_world():
    ur5 = robots.load("ur5")
    rotation, position = pin.rpy.rpyToMatrix(0.0, 0.0, 1.1), np.array([0.5, -0.3, 0.8])
    mounted = equipment.equip(ur5, mounting=equipment.mounting(position=position, rotation=rotation))
    q = _states(4)[0][0]
    tool = ur5.frame_id("tool0")
    pin.framesForwardKinematics(mounted.model, mounted.data, q)
    pin.framesForwardKinematics(ur5.model, ur5.data, q)
    expected = pin.SE3(rotation, position) * ur5.data.oMf[tool]
    assert np.abs(mounted.data.oMf[tool].homogeneous - expected.homogeneous).max() <= 1e-12
    bare_base = [c for c in robot_capsules(ur5) if c.joint == 0]
    placed_base = [c for c in robot_capsules(mounted) if c.joint == 0]
    assert bare_base and len(placed_base) == len(bare_base)
    for bare, placed in zip(bare_base, placed_base):
        assert placed.a == pytest.approx(rotation @ bare.a + position, abs=1e-12)


@pytest.mark.parametrize(
    ("call", "field", "words"),
    [
        (lambda: equipment.mounting(rotation=[[1, 0, 0], [0, 1, 0], [0, 0.5, 1]]), "rotation", "not a rotation matrix"),
        (lambda: equipment.mounting(rotation=np.diag([1.0, 1.0, -1.0])), "rotation", "reflection"),
        (lambda: equipment.mounting(orientation=[0.0, 0.0, 0.0, 2.0]), "orientation", "norm 2"),
        (lambda: equipment.mounting(position=[0.0, 0.0, 1e6]), "position", "position[2]"),
        (lambda: equipment.mounting(gravity=[0.0, 0.0, -1e3]), "gravity", "gravity[2]"),
        (lambda: equipment.payload(2000.0), "mass", "[0, 1000] kg"),
        (lambda: equipment.payload(1.0, (0.0, 0.0, 50.0)), "center_of_mass", "center_of_mass[2]"),
        (lambda: equipment.payload(1.0, inertia=[1.0, 1.0, 3.0, 0.0, 0.0, 0.0]), "inertia", "triangle inequality"),
        (lambda: equipment.payload(1.0, inertia=[1.0, 1.0, 1.0, 2.0, 0.0, 0.0]), "inertia", "not positive definite"),
        (lambda: equipment.payload(1.0, inertia=[[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]), "inertia", "symmetric"),
        (lambda: equipment.equip(robots.load("ur5"), equipment.payload(1.0, frame="nowhere")), "frame", "not a frame of ur5"),
    ],
)
def test_unphysical_equipment_is_refused_naming_the_quantity(call, field, words):
    with pytest.raises(equipment.InvalidEquipment) as raised:
        call()
    assert raised.value.field == field and words in raised.value.detail


def test_an_equipped_robot_reaches_a_worker_process_whole():
    """Methods that run in a child process receive the robot pickled."""
    import pickle

    ur5 = robots.load("ur5")
    load, base = equipment.payload(2.0, (0.0, 0.05, 0.1)), equipment.mounting(position=(1.0, 2.0, 0.5), orientation=(0.0, 0.0, 1.0, 0.0))
    sent = equipment.equip(ur5, load, base)
    received = pickle.loads(pickle.dumps(sent))
    q, qd, qdd = _states(5)
    assert np.abs(received.inverse_dynamics(q, qd, qdd) - sent.inverse_dynamics(q, qd, qdd)).max() == 0.0
    assert received.payload == load and received.mounting == base
    assert [c.a.tolist() for c in robot_capsules(received)] == [c.a.tolist() for c in robot_capsules(sent)]


def test_collocations_symbolic_dynamics_see_the_payload_and_the_mounting():
    """Collocation builds its own dynamics from the model (CasADi): they carry both too."""
    from toptraj.planners.generators.collocation.symbolic_dynamics import inverse_dynamics_function

    ur5 = robots.load("ur5")
    base = equipment.mounting(rotation=pin.rpy.rpyToMatrix(1.0, 0.4, -0.3), gravity=(0.0, 0.0, -9.81))
    equipped = equipment.equip(ur5, equipment.payload(MASS, COM, INERTIA), base)
    function = inverse_dynamics_function(equipped)
    q, qd, qdd = _states(6, 5)
    symbolic = np.array([np.asarray(function(*state)).ravel() for state in zip(q, qd, qdd)])
    assert np.abs(symbolic - equipped.rnea(q, qd, qdd)).max() <= 1e-9
    assert np.abs(symbolic - ur5.rnea(q, qd, qdd)).max() > 1.0
