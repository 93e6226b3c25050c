"""/v1/robots: the catalog, one robot, URDF uploads."""

from __future__ import annotations

from importlib import resources

import pytest

GEERING = resources.files("toptraj.robots").joinpath("urdf/geering_2r.urdf").read_text()

MINIMAL = """<robot name="one">
  <link name="base"/>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="{effort}" velocity="2"/>
  </joint>
  <link name="arm">{inertial}</link>
</robot>"""
INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>'


def test_health_and_docs(client):
    assert client.get("/health").json() == {"status": "ok"}
    assert client.get("/docs").status_code == 200
    spec = client.get("/openapi.json").json()
    assert "/v1/trajectories" in spec["paths"] and "/v1/robots" in spec["paths"]


def test_catalog_lists_paper_arms_and_example_arms(client):
    listing = {row["name"]: row for row in client.get("/v1/robots").json()}
    assert listing["geering_2r"] == {"name": "geering_2r", "dof": 2, "source": "bundled"}
    assert listing["ur5"]["source"] == "example-robot-data"
    assert listing["panda"]["dof"] == 7


def test_one_robot(client):
    body = client.get("/v1/robots/ur5").json()
    assert body["joint_names"][0] == "shoulder_pan_joint"
    assert body["end_effector"] == "tool0"
    assert body["limits"]["torque"] == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
    assert body["limits"]["acceleration"] == [10.0] * 6
    geering = client.get("/v1/robots/geering_2r").json()
    assert geering["limits"]["velocity"] == [None, None]  # the paper arm is torque-limited only
    missing = client.get("/v1/robots/nope")
    assert missing.status_code == 404 and "no robot named 'nope'" in missing.json()["detail"]


def test_upload_then_plan(client):
    created = client.post("/v1/robots", json={"urdf": GEERING})
    assert created.status_code == 201, created.text
    name = created.json()["name"]
    assert name.startswith("urdf-")
    assert client.post("/v1/robots", json={"urdf": GEERING}).json()["name"] == name  # same content, same id
    assert name in [row["name"] for row in client.get("/v1/robots").json()]
    planned = client.post(
        "/v1/trajectories",
        json={"robot": name, "path": {"waypoints": [[0, 0], [0.76, 0]]}, "timing": {"constraints": ["torque"]}},
    )
    assert planned.status_code == 200, planned.text
    bundled = client.post(
        "/v1/trajectories",
        json={"robot": "geering_2r", "path": {"waypoints": [[0, 0], [0.76, 0]]}, "timing": {"constraints": ["torque"]}},
    )
    assert planned.json()["duration"] == pytest.approx(bundled.json()["duration"], rel=1e-12)


def test_upload_under_a_name(client):
    urdf = MINIMAL.format(effort=5, inertial=INERTIAL)
    created = client.post("/v1/robots", json={"name": "my_arm", "urdf": urdf})
    assert created.status_code == 201 and created.json()["name"] == "my_arm"
    assert created.json()["limits"]["acceleration"] == [10.0]  # default rule: 2 rad/s over 0.2 s
    other = MINIMAL.format(effort=6, inertial=INERTIAL)
    assert client.post("/v1/robots", json={"name": "my_arm", "urdf": other}).status_code == 409
    assert client.post("/v1/robots", json={"name": "ur5", "urdf": urdf}).status_code == 409
    # a catalog name in other case: a request mistyping the catalog robot's would plan this one
    for alike, known in (("UR5", "ur5"), ("Geering_2R", "geering_2r")):
        refused = client.post("/v1/robots", json={"name": alike, "urdf": urdf})
        assert refused.status_code == 409, refused.text
        assert refused.json()["detail"] == f"name {alike!r} differs from the catalog robot {known!r} only in case; choose another"
    # an upload's name in other case, likewise
    refused = client.post("/v1/robots", json={"name": "My_Arm", "urdf": urdf})
    assert refused.status_code == 409, refused.text
    assert refused.json()["detail"] == "name 'My_Arm' differs from the upload 'my_arm' only in case; choose another"
    assert client.get("/v1/robots/My_Arm").status_code == 404


@pytest.mark.parametrize(
    "urdf, words",
    [
        ("<robot><link name='a'>", ["malformed XML"]),
        # a file's name where its text belongs
        ("/tmp/two_link.urdf", ["the URDF is the text '/tmp/two_link.urdf', not XML: give the file's contents, not its name", "--rawfile urdf FILE"]),
        ("robot", ["malformed XML"]),  # no file's name
        ("  \n ", ["the URDF is empty"]),
        ("<nothing/>", ["root element is <nothing>"]),
        (MINIMAL.format(effort=5, inertial=""), ["joint 'j'", "link 'arm' has no <inertial>"]),
        (MINIMAL.format(effort=0, inertial=INERTIAL), ["joint 'j'", "effort limit must be positive"]),
        (MINIMAL.format(effort="abc", inertial=INERTIAL), ["joint 'j'", "effort='abc' is not a number"]),
        (MINIMAL.replace('effort="{effort}" ', "").format(inertial=INERTIAL), ["joint 'j'", "no effort"]),
        (MINIMAL.replace("<limit", "<nolimit").format(effort=1, inertial=INERTIAL), ["joint 'j'", "has no <limit>"]),
        (MINIMAL.replace('type="revolute"', 'type="floating"').format(effort=1, inertial=INERTIAL), ["floating", "not supported"]),
        (MINIMAL.replace('<child link="arm"/>', '<child link="ghost"/>').format(effort=1, inertial=INERTIAL), ["link 'ghost'"]),
        ('<robot name="x"><link name="a"/></robot>', ["no revolute, continuous or prismatic joint"]),
        # a default namespace puts every element in it: the advice removes it
        (MINIMAL.replace("<robot ", '<robot xmlns="http://www.ros.org" ').format(effort=1, inertial=INERTIAL), ["remove the xmlns attribute"]),
        (MINIMAL.replace("</joint>", '<mimic joint="nope"/></joint>').format(effort=1, inertial=INERTIAL), ["joint 'j'", "<mimic joint='nope'>"]),
        (MINIMAL.replace("</joint>", "<mimic/></joint>").format(effort=1, inertial=INERTIAL), ["joint 'j'", "<mimic> names no joint"]),
        # a name is a CSV column on the answers' first line
        (MINIMAL.replace('name="j"', 'name="j&#10;k"').format(effort=1, inertial=INERTIAL), ["its name holds a control character"]),
        # a namespaced element below the root: no check reads it, and Pinocchio builds it
        (MINIMAL.replace('<joint name="j"', '<joint xmlns="urn:x" name="j"').format(effort=1, inertial=INERTIAL),
         ["the element <joint> is in the XML namespace 'urn:x'", "remove the xmlns attribute"]),
    ],
)
def test_bad_urdf_is_422_saying_what_and_where(client, urdf, words):
    response = client.post("/v1/robots", json={"urdf": urdf})
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    for word in words:
        assert word in detail, detail


def test_oversized_urdf(client):
    response = client.post("/v1/robots", json={"urdf": "<robot>" + " " * 1_200_000 + "</robot>"})
    assert response.status_code == 422
    assert "urdf" in response.json()["detail"]


def _two_joints(first_child: str = "l1", second_child: str = "l2", names: tuple[str, str] = ("j1", "j2"), mimic: str = "") -> str:
    link = '<link name="{}">' + INERTIAL.replace("<mass", '<origin xyz="0 0 0.25"/><mass') + "</link>"
    joint = (
        '<joint name="{}" type="revolute"><parent link="{}"/><child link="{}"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>'
        '<limit lower="-2" upper="2" effort="50" velocity="2"/>{}</joint>'
    )
    return (
        '<robot name="two"><link name="base"/>' + link.format(first_child) + link.format(second_child)
        + joint.format(names[0], "base", first_child, "") + joint.format(names[1], first_child, second_child, mimic) + "</robot>"
    )


def _plan(client, robot: str, **output):
    return client.post("/v1/trajectories", json={
        "robot": robot, "path": {"kind": "waypoints", "waypoints": [[0, 0], [1, 1]]},
        "timing": {"method": "toppra", "constraints": ["velocity", "acceleration", "torque"]}, "output": {"dt": 0.01, **output},
    })


def test_a_link_named_as_a_joint_plans(client):
    """A URDF may give a link and a joint one name (here the last link and the first joint): the
    tool is the link, and planning and the skeleton work (pinocchio's lookup by name refused
    the ambiguity, a 500 on every request)."""
    assert client.post("/v1/robots", json={"name": "shared_name", "urdf": _two_joints(second_child="j1")}).status_code == 201
    planned = _plan(client, "shared_name")
    assert planned.status_code == 200, planned.text
    assert client.post("/v1/robots/shared_name/skeleton", json={"q": [[0, 0], [1, 1]]}).status_code == 200


def test_a_mimic_joint_is_told(client):
    created = client.post("/v1/robots", json={"urdf": _two_joints(mimic='<mimic joint="j1" multiplier="-1"/>')})
    assert created.status_code == 201, created.text
    assert any("joint 'j2' mimics joint 'j1'" in note and "times" in note for note in created.json()["notes"]), created.json()["notes"]
    locked = client.post("/v1/robots", json={"urdf": _two_joints(mimic='<mimic joint="j1"/>'), "locked_joints": {"j2": 0.0}})
    assert locked.status_code == 201 and not any("mimic" in note for note in locked.json()["notes"])


def test_a_joint_inside_another_element_is_none_of_the_robots(client):
    """A ``<joint>`` inside a ``<gazebo>`` (with a xacro expression left in it) is not read as
    the robot's: no mimic note about it, no 500 on its number."""
    nested = '<gazebo><joint name="g"><mimic joint="j1" multiplier="${2*pi}"/></joint></gazebo></robot>'
    created = client.post("/v1/robots", json={"urdf": _two_joints().replace("</robot>", nested)})
    assert created.status_code == 201, created.text
    assert not any("mimic" in note for note in created.json()["notes"])


def test_csv_quotes_a_joint_name_that_needs_it(client):
    import csv
    import io

    names = ("a,b", "x&quot;y")  # the XML's escape of x"y
    assert client.post("/v1/robots", json={"name": "odd_names", "urdf": _two_joints(names=names)}).status_code == 201
    text = _plan(client, "odd_names", format="csv").text
    rows = list(csv.reader(line for line in io.StringIO(text) if not line.startswith("#")))
    assert rows[0][:3] == ["t", "q.a,b", 'q.x"y']
    assert {len(row) for row in rows} == {9}
