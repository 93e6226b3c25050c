"""Hostile uploads: YAML and JSON limits that try to exhaust time or memory (alias bombs, deep
nesting, huge numbers), keys and values of the wrong type, and limits outside their accepted
range from any source (joint_limits.yaml, URDF): each is a 422 that says what and where, in
bounded time and text, never a 500."""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import pytest

from toptraj import robots
from toptraj.robots.bounded_yaml import MAX_ALIASES, MAX_CHARS, MAX_DEPTH, MAX_NODES
from toptraj.robots.catalog import example_urdf_path
from toptraj.robots.errors import MAX_DETAIL_CHARS, InvalidURDF, excerpt
from toptraj.robots.ranges import LIMITS
from toptraj.robots.upload_options import UploadOptions

UR5 = Path(example_urdf_path("ur5")).read_text()
KEYS = {"velocity": "max_velocity", "acceleration": "max_acceleration", "jerk": "max_jerk", "torque": "max_effort"}
FLAGS = {"velocity": "has_velocity_limits", "acceleration": "has_acceleration_limits", "jerk": "has_jerk_limits",
         "torque": "has_effort_limits"}


def _entry(body: str) -> str:
    return f"joint_limits:\n  elbow_joint:\n{body}"


def _bomb(depth: int, width: int = 10) -> str:
    """Anchors a0..a{depth}, each a list of ``width`` aliases of the one before: 10^depth items."""
    lines = ["a0: &a0 [1.0]"]
    lines += [f"a{k}: &a{k} [{', '.join([f'*a{k - 1}'] * width)}]" for k in range(1, depth + 1)]
    return "\n".join(lines) + f"\njoint_limits:\n  elbow_joint:\n    has_velocity_limits: true\n    max_velocity: *a{depth}\n"


def _post(client, joint_limits, name="ur5_hostile"):
    started = time.perf_counter()
    response = client.post("/v1/robots", json={"name": name, "urdf": UR5, "joint_limits": joint_limits})
    return response, time.perf_counter() - started


HOSTILE_YAML = {
    # Time and memory.
    "alias bomb depth 8": (_bomb(8), f"more than {MAX_NODES} values once its aliases are expanded"),
    "alias bomb depth 9": (_bomb(9), f"more than {MAX_NODES} values once its aliases are expanded"),
    "many aliases": ("a: &a 1\nb: [" + ", ".join(["*a"] * (MAX_ALIASES + 1)) + "]\n", f"more than {MAX_ALIASES} aliases"),
    "merge-key bomb": ("m0: &m0 {k: 1}\n" + "".join(f"m{k}: &m{k} {{<<: [*m{k - 1}, *m{k - 1}], k{k}: 1}}\n" for k in range(1, 30)),
                       "once its aliases are expanded"),
    "alias cycle": ("joint_limits: &j {elbow_joint: *j}\n", "a cycle"),
    "nesting 5000 deep (flow)": ("joint_limits: " + "[" * 5000 + "]" * 5000, f"more than {MAX_DEPTH} levels deep"),
    "nesting 5000 deep (mappings)": ("joint_limits: " + "{a: " * 5000 + "1" + "}" * 5000, f"more than {MAX_DEPTH} levels deep"),
    "huge document": ("# " + "x" * MAX_CHARS + "\njoint_limits: {}\n", f"at most {MAX_CHARS} are read"),
    "huge scalar": ("joint_limits: {" + "j" * 5000 + ": {}}\n", "a value of 5000 characters"),
    # Numbers.
    "integer of 401 digits": (_entry("    has_velocity_limits: true\n    max_velocity: " + "9" * 401 + "\n"),
                              "an integer of 401 characters"),
    "sexagesimal integer": (_entry("    has_velocity_limits: true\n    max_velocity: " + ":".join(["59"] * 40) + "\n"),
                            "an integer of 119 characters"),
    "float that overflows": (_entry("    has_velocity_limits: true\n    max_velocity: 1" + "0" * 400 + ".0\n"),
                             "max_velocity must be a finite number, got inf"),
    ".nan": (_entry("    has_acceleration_limits: true\n    max_acceleration: .nan\n"), "must be a finite number, got nan"),
    ".inf": (_entry("    has_jerk_limits: true\n    max_jerk: .inf\n"), "must be a finite number, got inf"),
    "-.inf": (_entry("    has_effort_limits: true\n    max_effort: -.inf\n"), "must be a finite number, got -inf"),
    "boolean for a number": (_entry("    has_velocity_limits: true\n    max_velocity: true\n"), "must be a finite number, got True"),
    "string for a number": (_entry("    has_velocity_limits: true\n    max_velocity: fast\n"), "must be a finite number, got 'fast'"),
    "list for a number": (_entry("    has_velocity_limits: true\n    max_velocity: [1.0, 2.0]\n"), "got a list of 2 items"),
    "timestamp for a number": (_entry("    has_velocity_limits: true\n    max_velocity: 2001-12-14\n"), "got a value of type date"),
    "binary for a number": (_entry("    has_velocity_limits: true\n    max_velocity: !!binary aGVsbG8=\n"), "got b'hello'"),
    # Keys, tags, documents.
    "integer key at top level": ("joint_limits: {}\n1: 2\n", "the key '1' is not a string"),
    "boolean key at top level": ("joint_limits: {}\nyes: 2\n", "the key 'yes' is not a string"),
    "null key in a joint entry": (_entry("    has_velocity_limits: true\n    ~: 1.0\n"), "the key '~' is not a string"),
    "integer key in a joint entry": (_entry("    has_velocity_limits: true\n    max_velocity: 1.0\n    3: 1.0\n"),
                                     "the key '3' is not a string"),
    "sequence key": (_entry("    ? [a, b]\n    : 1.0\n"), "the key a sequence is not a string"),
    "integer joint name": ("joint_limits:\n  7: {has_velocity_limits: true, max_velocity: 1.0}\n", "the key '7' is not a string"),
    "duplicate key": (_entry("    has_velocity_limits: true\n    max_velocity: 1.0\n    max_velocity: 2.0\n"),
                      "the key 'max_velocity' appears twice"),
    "duplicate joint": ("joint_limits:\n  elbow_joint: {}\n  elbow_joint: {}\n", "the key 'elbow_joint' appears twice"),
    "python tag": ("joint_limits: !!python/object/apply:os.system [true]\n", "could not determine a constructor"),
    "local tag": ("joint_limits: !limits {}\n", "could not determine a constructor"),
    "two documents": ("joint_limits: {}\n---\njoint_limits: {}\n", "expected a single document"),
    "not YAML": ("joint_limits: [\n", "not valid YAML at line"),
}


@pytest.mark.parametrize("text, fragment", HOSTILE_YAML.values(), ids=HOSTILE_YAML.keys())
def test_hostile_yaml_is_a_422_in_bounded_time_and_text(client, text, fragment):
    response, seconds = _post(client, text)
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    detail = response.json()["detail"]
    assert fragment in detail
    assert len(detail) <= MAX_DETAIL_CHARS
    assert seconds < 2.0


def _nested(depth: int) -> list:
    value: list = []
    for _ in range(depth):
        value = [value]
    return value


HOSTILE_JSON = {
    "integer of 401 digits": ({"elbow_joint": {"has_velocity_limits": True, "max_velocity": 10**400}},
                              "max_velocity must be a finite number, got an integer of about 401 digits"),
    "many values": ({"elbow_joint": {"has_velocity_limits": True, "max_velocity": [0.5] * (MAX_NODES + 1)}},
                    f"more than {MAX_NODES} values"),
    "boolean for a number": ({"elbow_joint": {"has_jerk_limits": True, "max_jerk": False}}, "got False"),
    "subnormal": ({"elbow_joint": {"has_jerk_limits": True, "max_jerk": 5e-324}}, "the jerk limit 4.94066e-324 rad/s^3"),
}


@pytest.mark.parametrize("limits, fragment", HOSTILE_JSON.values(), ids=HOSTILE_JSON.keys())
def test_hostile_json_limits_are_a_422(client, limits, fragment):
    response, seconds = _post(client, {"joint_limits": limits})
    assert response.status_code == 422, response.text
    assert fragment in response.json()["detail"] and seconds < 2.0


def test_json_limits_nested_deeper_than_a_request_are_refused_before_they_are_read(client):
    """Limits given as JSON in the body nest the body itself: more than a request may is the
    body's 400, before the body is parsed (the YAML text's own bound is tested above)."""
    from toptraj.service.strict_json import MAX_DEPTH as BODY_DEPTH

    response, seconds = _post(client, {"elbow_joint": {"has_velocity_limits": True, "max_velocity": _nested(200)}})
    assert response.status_code == 400, response.text
    assert response.json()["detail"] == f"the body is nested too deeply: it nests arrays and objects 204 deep; a request nests at most {BODY_DEPTH} levels"
    assert seconds < 2.0


@pytest.mark.parametrize("kind", LIMITS)
@pytest.mark.parametrize("side", ["below", "above"])
def test_a_yaml_limit_outside_its_range_is_a_422_naming_joint_limit_and_source(client, kind, side):
    accepted = LIMITS[kind]
    value = {"below": accepted.low / 10, "above": accepted.high * 10}[side]
    text = _entry(f"    {FLAGS[kind]}: true\n    {KEYS[kind]}: {value!r}\n")
    response, _ = _post(client, text)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert f"joint_limits.elbow_joint.{KEYS[kind]}: joint 'elbow_joint': the {kind} limit {value:g}" in detail
    assert f"from joint_limits.yaml is outside the accepted range {accepted.describe()}" in detail


@pytest.mark.parametrize("value", ["1e-300", "1.0e-300", "1e308", "5e-324"])
def test_the_issue_s_tiny_and_huge_accelerations_are_refused(client, value):
    response, _ = _post(client, _entry(f"    has_acceleration_limits: true\n    max_acceleration: {value}\n"))
    assert response.status_code == 422, response.text
    assert "the acceleration limit" in response.json()["detail"] and "joint_limits.yaml" in response.json()["detail"]


def test_yaml_floats_without_a_dot_are_numbers(client):
    """``1e-3`` is a float in YAML 1.2 and in MoveIt's reader; YAML 1.1 would read a string."""
    response, _ = _post(client, _entry("    has_jerk_limits: true\n    max_jerk: 5e+2\n"), name="ur5_exponent")
    assert response.status_code == 201, response.text
    robot = response.json()
    assert robot["limits"]["jerk"][2] == 500.0 and robot["limit_sources"]["jerk"][2] == "joint_limits.yaml"


def test_anchors_and_merge_keys_within_the_bounds_work(client):
    text = (
        "joint_limits:\n"
        "  shoulder_pan_joint: &defaults {has_acceleration_limits: true, max_acceleration: 4.0}\n"
        "  elbow_joint: {<<: *defaults, has_jerk_limits: true, max_jerk: 80.0}\n"
        "  wrist_1_joint: *defaults\n"
    )
    response, _ = _post(client, text, name="ur5_anchors")
    assert response.status_code == 201, response.text
    robot = response.json()
    assert robot["limits"]["acceleration"][0] == 4.0 and robot["limits"]["acceleration"][2:4] == [4.0, 4.0]
    assert robot["limits"]["jerk"][2] == 80.0 and robot["limit_sources"]["jerk"][3] != "joint_limits.yaml"


@pytest.mark.parametrize("method", ["ruckig", "toppra", "min_cost", "phase_plane"])
@pytest.mark.parametrize("end", ["low", "high"])
def test_limits_at_either_end_of_their_ranges_plan(client, method, end):
    """An upload whose acceleration and jerk limits sit at an end of their ranges plans with each
    method (a 200 whose duration follows the limit), never a 5xx."""
    pick = {"low": lambda r: r.low, "high": lambda r: r.high}[end]
    acceleration, jerk = pick(LIMITS["acceleration"]), pick(LIMITS["jerk"])
    text = "joint_limits:\n" + "".join(
        f"  {joint}: {{has_acceleration_limits: true, max_acceleration: {acceleration!r}, has_jerk_limits: true, "
        f"max_jerk: {jerk!r}}}\n"
        for joint in ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
                      "wrist_3_joint")
    )
    name = f"ur5_{end}_end"
    uploaded, _ = _post(client, text, name=name)
    assert uploaded.status_code in (201, 409) and client.get(f"/v1/robots/{name}").status_code == 200
    constraints = ["velocity", "acceleration", "jerk"] if method == "ruckig" else ["velocity", "acceleration"]
    body = {
        "robot": name,
        "path": {"kind": "waypoints", "waypoints": [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]]},
        "timing": {"method": method, "constraints": constraints},
        "output": {"dt": 1.0 if end == "low" else 0.01},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 200, response.text
    duration = response.json()["duration"]
    if end == "low":
        # Rest to rest over the largest joint move (0.8 rad) at 1e-6 rad/s^2: the speed limit is
        # never reached, and bang-bang takes 2 sqrt(d / a) (jerk limits lengthen it slightly).
        assert duration == pytest.approx(2.0 * (0.8 / 1e-6) ** 0.5, rel=0.02)
    else:
        # Acceleration is then almost no bound: the velocity limit (3.15 rad/s) sets the time,
        # d / v at least; min_cost's collocation grid places its speed changes less finely (+16 %).
        assert 0.8 / 3.15 * (1 - 1e-3) <= duration <= 0.8 / 3.15 * 1.2


def test_a_urdf_limit_outside_its_range_is_a_422_naming_the_urdf(client):
    urdf = UR5.replace('velocity="3.15"', 'velocity="3150.0"', 1)
    assert urdf != UR5
    response = client.post("/v1/robots", json={"name": "ur5_fast", "urdf": urdf})
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert "joint 'shoulder_pan_joint'" in detail
    assert "velocity limit 3150 rad/s (m/s for prismatic) in the URDF is outside the accepted range [1e-06, 1000]" in detail


def test_excerpt_is_bounded_whatever_the_value():
    nested: list = []
    for _ in range(10_000):
        nested = [nested]
    shared = [1.0]
    for _ in range(30):
        shared = [shared, shared]  # 2^30 items as a repr would walk them
    assert excerpt(nested) == "a list of 1 item"
    assert excerpt(shared) == "a list of 2 items"
    assert excerpt(10**5000) == "an integer of about 5001 digits"
    assert excerpt(10**29) == repr(10**29)
    assert excerpt("x" * 1_000_000, 10) == "'xxxxxxxxx... (1000000 characters)"
    assert excerpt("short") == "'short'"
    assert excerpt({"a": 1}) == "a mapping of 1 key"
    assert excerpt(object()) == "a value of type object"


def test_a_stored_upload_whose_limits_left_their_range_no_longer_loads(tmp_path):
    """Options stored before the ranges were checked (1e-300 rad/s^2) are checked when the
    robot is built: the load names the joint, the limit and its source instead of planning."""
    previous = robots.upload_store()
    try:
        store = robots.configure_uploads(tmp_path)
        options = UploadOptions(joint_limits={"elbow_joint": {"acceleration": 1e-300}})
        store.put("ur5_stale", hashlib.sha256(UR5.encode()).hexdigest(), UR5, 6, options.to_json())
        with pytest.raises(InvalidURDF) as raised:
            robots.load("ur5_stale")
        assert "the stored upload 'ur5_stale' no longer passes the checks" in raised.value.detail
        assert "joint 'elbow_joint': the acceleration limit 1e-300 rad/s^2 from joint_limits.yaml" in raised.value.detail
    finally:
        robots.configure_uploads(previous.data_dir, max_uploads=previous.max_uploads, max_bytes=previous.max_bytes)


@pytest.mark.parametrize("levels, refused", [(20, False), (600, True)])
def test_elements_nested_deeper_than_a_urdf_has_are_refused_saying_so(client, levels, refused):
    """Pinocchio's parser refused some 500 nested elements with "not a valid URDF model" and no
    reason; deeper than 32 levels is refused naming the nesting, a few are read as ever."""
    urdf = (Path(__file__).resolve().parents[1] / "data" / "pendulum_1r.urdf").read_text()
    urdf = urdf.replace('<link name="base"/>', '<link name="base">' + "<junk>" * levels + "</junk>" * levels + "</link>")
    answer = client.post("/v1/robots", json={"name": f"nested_{levels}", "urdf": urdf})
    if not refused:
        assert answer.status_code == 201, answer.text[:300]
        return
    assert answer.status_code == 422, answer.text[:300]
    assert "nests elements 33 levels deep and more (robot > link > junk > junk)" in answer.json()["detail"], answer.json()["detail"]
