"""POST /v1/robots refuses URDFs whose physics no body has, whose numbers are not finite or out of
range, or whose links do not form a tree, with a 422 naming the link or joint; names and error
bodies stay short whatever the request holds."""

from __future__ import annotations

from importlib import resources

import pytest

from toptraj.robots.catalog import BUNDLED, EXAMPLE_ARMS, example_urdf_path
from toptraj.robots.urdf_check import check_urdf

INERTIA = 'ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"'


def arm(
    inertia: str = INERTIA,
    mass: str = "1",
    origin: str = 'xyz="0 0 0.1" rpy="0 0 0"',
    inertial_origin: str = 'xyz="0.2 0 0"',
    limit: str = 'lower="-1" upper="1" effort="5" velocity="2"',
    axis: str = "0 0 1",
    extra_joint: str = "",
    arm_link: str = "",
) -> str:
    """A one-joint arm whose pieces a test may replace."""
    return f"""<robot name="one">
  <link name="base"/>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/><origin {origin}/><axis xyz="{axis}"/>
    <limit {limit}/>{extra_joint}
  </joint>
  <link name="arm">
    <inertial><origin {inertial_origin}/><mass value="{mass}"/><inertia {inertia}/></inertial>{arm_link}
  </link>
</robot>"""


def _short_name(k: int) -> str:
    digits = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
    name = digits[k % 52]
    k //= 52
    while k:
        name += digits[k % 62]
        k //= 62
    return name


def fixed_chain(n_links: int) -> str:
    """A moving joint, then a chain of ``n_links`` links joined by fixed joints (names short
    enough that 10,000 links fit the 1,000,000 characters an upload may have)."""
    parts = [
        '<robot name="c"><link name="base"/><joint name="move" type="revolute"><parent link="base"/><child link="a"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>',
        f'<link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia {INERTIA}/></inertial></link>',
    ]
    for k in range(1, n_links):
        parent, child = _short_name(k - 1), _short_name(k)
        parts.append(f'<link name="{child}"/><joint name="{child}" type="fixed"><parent link="{parent}"/><child link="{child}"/></joint>')
    return "".join(parts) + "</robot>"


def two_joint_cycle() -> str:
    return f"""<robot name="loop">
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
  <link name="arm"><inertial><mass value="1"/><inertia {INERTIA}/></inertial></link>
  <link name="a"/><link name="b"/>
  <joint name="loop_ab" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="loop_ba" type="fixed"><parent link="b"/><child link="a"/></joint>
</robot>"""


INVALID = {
    "nan inertia": (arm(inertia=INERTIA.replace('ixx="0.1"', 'ixx="nan"')), ["link 'arm'", "ixx='nan' is not finite"]),
    "inf inertia": (arm(inertia=INERTIA.replace('iyz="0"', 'iyz="-inf"')), ["link 'arm'", "not finite"]),
    "1e308 inertia": (arm(inertia=INERTIA.replace('izz="0.1"', 'izz="1e308"')), ["link 'arm'", "izz=1e+308"]),
    "inertia not positive definite": (
        arm(inertia='ixx="0.1" iyy="0.1" izz="0.1" ixy="0.5" ixz="0" iyz="0"'),
        ["link 'arm'", "not positive definite"],
    ),
    "negative moment": (arm(inertia='ixx="-0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"'), ["link 'arm'", "not positive definite"]),
    "triangle inequality": (
        arm(inertia='ixx="0.1" iyy="0.1" izz="0.5" ixy="0" ixz="0" iyz="0"'),
        ["link 'arm'", "triangle inequality"],
    ),
    "inertia entry missing": (arm(inertia='ixx="0.1" iyy="0.1" izz="0.1"'), ["link 'arm'", "ixy is missing"]),
    "zero mass with inertia": (arm(mass="0"), ["link 'arm'", "mass must be positive"]),
    "negative mass": (arm(mass="-1"), ["link 'arm'", "mass -1 kg is outside"]),
    "nan mass": (arm(mass="NaN"), ["link 'arm'", "not finite"]),
    "1e308 mass": (arm(mass="1e308"), ["link 'arm'", "mass 1e+308 kg"]),
    "1e308 joint origin": (arm(origin='xyz="1e308 0 0"'), ["joint 'j'", "<origin> xyz"]),
    "1e308 inertial origin": (arm(inertial_origin='xyz="0 1e308 0"'), ["link 'arm'", "<origin> xyz"]),
    "nan rpy": (arm(origin='xyz="0 0 0" rpy="0 nan 0"'), ["joint 'j'", "rpy='nan' is not finite"]),
    "origin of two numbers": (arm(origin='xyz="0 0"'), ["joint 'j'", "must hold three numbers"]),
    "hex number": (arm(mass="0x1p3"), ["link 'arm'", "is not a number"]),
    "effort 1e-308": (arm(limit='lower="-1" upper="1" effort="1e-308" velocity="2"'), ["joint 'j'", "effort limit 1e-308"]),
    "velocity 1e300": (arm(limit='lower="-1" upper="1" effort="5" velocity="1e300"'), ["joint 'j'", "velocity limit 1e+300"]),
    "position limit 1e300": (arm(limit='lower="-1e300" upper="1" effort="5" velocity="2"'), ["joint 'j'", "lower position limit"]),
    "position limit inf": (arm(limit='lower="-inf" upper="1" effort="5" velocity="2"'), ["joint 'j'", "lower='-inf' is not finite"]),
    "negative damping": (arm(extra_joint='<dynamics damping="-1"/>'), ["joint 'j'", "damping -1"]),
    "nan friction": (arm(extra_joint='<dynamics friction="nan"/>'), ["joint 'j'", "friction='nan' is not finite"]),
    "zero axis": (arm(axis="0 0 0"), ["joint 'j'", "<axis>"]),
    "huge box": (arm(arm_link='<collision><geometry><box size="1 1e308 1"/></geometry></collision>'), ["link 'arm'", "<box>"]),
    "negative radius": (arm(arm_link='<visual><geometry><sphere radius="-1"/></geometry></visual>'), ["link 'arm'", "<sphere>"]),
    "mass on the joint axis only": (
        arm(inertia='ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"', inertial_origin='xyz="0 0 0.3"'),
        ["joint 'j'", "no inertia about its axis"],
    ),
    "10,000 fixed links": (fixed_chain(10_000), ["10001 links", "at most 1000"]),
    "two-joint cycle": (two_joint_cycle(), ["joint 'loop_", "form a cycle"]),
    "two parents": (
        arm(arm_link="").replace(
            "</robot>", '<link name="x"/><joint name="again" type="fixed"><parent link="x"/><child link="arm"/></joint></robot>'
        ),
        ["joint 'again'", "link 'arm' is already the child of joint 'j'"],
    ),
    "two roots": (arm().replace("</robot>", '<link name="stray"/></robot>'), ["'base'", "'stray'", "single root"]),
    "duplicate link": (arm().replace("</robot>", '<link name="arm"/></robot>'), ["two <link> elements are named 'arm'"]),
    "doctype": ('<!DOCTYPE robot [<!ENTITY m "1">]>' + arm(mass="&m;"), ["<!DOCTYPE>"]),
}


@pytest.mark.parametrize("case", list(INVALID))
def test_invalid_physics_or_structure_is_422_naming_the_place(client, case):
    urdf, words = INVALID[case]
    assert len(urdf) < 1_000_000
    response = client.post("/v1/robots", json={"urdf": urdf})
    assert response.status_code == 422, response.text
    assert response.headers["content-type"] == "application/problem+json"
    detail = response.json()["detail"]
    for word in words:
        assert word in detail, detail


def test_a_long_chain_of_fixed_links_is_walked_without_recursion(client):
    created = client.post("/v1/robots", json={"urdf": fixed_chain(999)})
    assert created.status_code == 201, created.text
    assert created.json()["dof"] == 1


def test_physically_valid_limits_cases_upload():
    """A point mass, a slender rod and massless frames are bodies (or none): accepted."""
    point_mass = arm(inertia='ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"')
    rod = arm(inertia='ixx="0" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"')
    lamina = arm(inertia='ixx="0.0833" iyy="0.0833" izz="0.1667" ixy="0" ixz="0" iyz="0"')  # printed to 3 digits
    massless = arm(arm_link="").replace(
        "</robot>",
        '<link name="tcp"><inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link><joint name="t" type="fixed"><parent link="arm"/><child link="tcp"/></joint></robot>',
    )
    for urdf in (point_mass, rod, lamina, massless):
        assert check_urdf(urdf).nv == 1


@pytest.mark.parametrize("name", [*BUNDLED, *EXAMPLE_ARMS])
def test_every_catalog_urdf_passes_the_checks(name):
    if name in BUNDLED:
        urdf = resources.files("toptraj.robots").joinpath(f"urdf/{name}.urdf").read_text()
    else:
        with open(example_urdf_path(EXAMPLE_ARMS[name].loader)) as handle:
            urdf = handle.read()
    assert check_urdf(urdf).nv >= 1


@pytest.mark.parametrize("name", ["x" * 10_000, "bad name!", "9lives", "ünïcode", ""])
def test_invalid_name_is_422_without_echoing_it(client, name):
    urdf = arm()
    response = client.post("/v1/robots", json={"name": name, "urdf": urdf})
    assert response.status_code == 422, response.text
    body = response.text
    assert len(body) < 1_000 and "x" * 100 not in body
    assert "name" in response.json()["detail"]


def test_a_name_clash_stays_409(client):
    assert client.post("/v1/robots", json={"name": "clash_arm", "urdf": arm()}).status_code == 201
    assert client.post("/v1/robots", json={"name": "clash_arm", "urdf": arm()}).status_code == 201  # same text
    other = arm(mass="2")
    assert client.post("/v1/robots", json={"name": "clash_arm", "urdf": other}).status_code == 409
    assert client.post("/v1/robots", json={"name": "panda", "urdf": other}).status_code == 409


BIG = 900_000


@pytest.mark.parametrize(
    "urdf",
    [
        arm(limit=f'lower="-1" upper="1" effort="{"x" * BIG}" velocity="2"'),  # not a number
        arm(limit=f'lower="-1" upper="1" effort="{"9" * BIG}" velocity="2"'),  # a number that overflows
        arm().replace('<child link="arm"/>', f'<child link="{"g" * BIG}"/>'),  # a dangling link name
        arm().replace('name="j"', f'name="{"j" * BIG}"').replace("<mass", "<nomass"),  # a long joint name
        f"<{'r' * BIG}/>",  # a long root tag
        "<robot>" + "<" * BIG,  # malformed XML
    ],
    ids=["word", "digits", "link name", "joint name", "root tag", "malformed"],
)
def test_error_bodies_never_echo_the_request(client, urdf):
    response = client.post("/v1/robots", json={"urdf": urdf})
    assert response.status_code == 422, response.text[:300]
    assert len(response.content) < 2_000, response.text[:300]


def test_an_unknown_robot_404_lists_the_catalog_but_no_upload(client):
    assert client.post("/v1/robots", json={"name": "someone_elses_arm", "urdf": arm()}).status_code == 201
    assert "someone_elses_arm" in [row["name"] for row in client.get("/v1/robots").json()]
    for response in (
        client.get("/v1/robots/nope"),
        client.post("/v1/trajectories", json={"robot": "nope", "path": {"waypoints": [[0], [0.1]]}}),
    ):
        assert response.status_code == 404
        detail = response.json()["detail"]
        assert "someone_elses_arm" not in detail
        assert "ur5" in detail and "GET /v1/robots" in detail
    # A name longer than any robot's is refused by the request schema, without echoing it.
    long_name = client.post("/v1/trajectories", json={"robot": "r" * 100_000, "path": {"waypoints": [[0], [0.1]]}})
    assert long_name.status_code == 422 and len(long_name.content) < 2_000
