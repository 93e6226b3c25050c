"""Pairs of links allowed to touch: an SRDF's disable_collisions or a list of pairs, read within
bounds, given with an upload, and applied by the self-collision check."""

from __future__ import annotations

import pytest

from tests.paths import ROOT
from toptraj.robots.srdf import MAX_PAIRS, MAX_SRDF_CHARS, InvalidCollisionList, allowed_pairs, shipped_pairs, srdf_pairs

ARM_3R = (ROOT / "robots" / "urdf" / "lecture_3r.urdf").read_text()
SRDF = """<?xml version="1.0"?>
<robot name="lecture_3r">
  <group name="arm"><chain base_link="base" tip_link="hand"/></group>
  <disable_collisions link1="turret" link2="forearm" reason="Never"/>
  <disable_collisions link1="forearm" link2="hand" reason="Adjacent"/>
</robot>
"""
#: The forearm folds down onto the turret (their capsules overlap from elbow = 1.3 rad).
FOLDING = {"kind": "waypoints", "waypoints": [[0.0, 2.8, 0.0], [0.0, 2.8, 2.0]], "self_collision": True}
BILLION_LAUGHS = (
    '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>'
    '<robot><disable_collisions link1="&b;" link2="x"/></robot>'
)


def test_an_srdf_gives_its_disable_collisions_in_a_canonical_order():
    assert srdf_pairs(SRDF) == {("forearm", "turret"), ("forearm", "hand")}
    assert allowed_pairs([["turret", "forearm"]]) == {("forearm", "turret")}
    # example-robot-data's SRDF for ur5
    ur5 = shipped_pairs("ur5")
    assert ur5 is not None and len(ur5) == 10 and ("forearm_link", "wrist_1_link") in ur5


@pytest.mark.parametrize(
    ("given", "words"),
    [
        (BILLION_LAUGHS, "DOCTYPE"),
        ("<robot>" + " " * MAX_SRDF_CHARS + "</robot>", f"at most {MAX_SRDF_CHARS} characters"),
        ("<robot>" + "<a>" * 20 + "</a>" * 20 + "</robot>", "levels"),
        ("<robot>" + '<disable_collisions link1="a"/>' + "</robot>", "link2"),
        ("<robot><disable_collisions", "not well-formed"),
        ("<robot>" + "".join(f'<disable_collisions link1="a{k}" link2="b"/>' for k in range(MAX_PAIRS + 1)) + "</robot>", "pairs"),
        ([["a", "b", "c"]], "pair"),
        ([["a", 3]], "link name"),
        ({"a": "b"}, "SRDF text or a list"),
    ],
)
def test_a_hostile_or_malformed_list_is_refused_saying_why(given, words):
    with pytest.raises(InvalidCollisionList) as refused:
        allowed_pairs(given)
    assert words in refused.value.detail


def test_an_uploads_srdf_allows_its_pairs_along_a_path(client):
    body = {"robot": "plain_3r", "path": FOLDING}
    assert client.post("/v1/robots", json={"name": "plain_3r", "urdf": ARM_3R}).status_code == 201
    refused = client.post("/v1/trajectories", json=body)
    assert refused.status_code == 422, refused.text
    problem = refused.json()
    assert {problem["link_a"], problem["link_b"]} == {"turret", "forearm"} and 0.0 < problem["s"] < 1.0
    assert f"s = {problem['s']:.4g}" in problem["detail"]
    # the same path without the check: served
    unchecked = {"robot": "plain_3r", "path": {**FOLDING, "self_collision": False}}
    assert client.post("/v1/trajectories", json=unchecked).status_code == 200
    for name, allowed in (("srdf_3r", SRDF), ("listed_3r", [["forearm", "turret"]])):
        created = client.post("/v1/robots", json={"name": name, "urdf": ARM_3R, "allowed_collisions": allowed})
        assert created.status_code == 201, created.text
        served = client.post("/v1/trajectories", json={"robot": name, "path": FOLDING})
        assert served.status_code == 200, served.text


@pytest.mark.parametrize(
    ("allowed", "words"),
    [
        ([["turret", "elbow"]], "'elbow', which is not a link"),
        (BILLION_LAUGHS, "DOCTYPE"),
        ([["a"]], "allowed_collisions[0] must be a pair [link, link], got a list of 1 item"),
        ([["turret", "turret"]], "allowed_collisions[0] pairs link 'turret' with itself, which is never checked"),
        ([[1, 2]], "allowed_collisions[0][0] must be a link name"),
    ],
)
def test_an_upload_with_a_bad_list_is_refused_naming_it(client, allowed, words):
    """In the list's own words: pydantic's union named the type (``list[list[str]]``) and said
    "Input should be a valid string" of a list; a link paired with itself was accepted."""
    refused = client.post("/v1/robots", json={"name": "bad_3r", "urdf": ARM_3R, "allowed_collisions": allowed})
    assert refused.status_code == 422, refused.text
    assert words in refused.text and "list[list[str]]" not in refused.text and "valid string" not in refused.text


def test_the_pairs_allowed_at_upload_hold_with_a_payload_a_mounting_and_in_a_cell(client):
    """The equipped robot (payload, mounting; every arm of a cell has a base) kept the upload's
    model but dropped its list: the pair allowed was refused again, with the advice to allow it."""
    assert client.post("/v1/robots", json={"name": "listed_3r_eq", "urdf": ARM_3R, "allowed_collisions": [["forearm", "turret"]]}).status_code == 201
    for equipment in ({"payload": {"mass": 0.1}}, {"mounting": {"position": [0.0, 0.0, 0.5]}}):
        served = client.post("/v1/trajectories", json={"robot": "listed_3r_eq", "path": FOLDING, **equipment})
        assert served.status_code == 200, (equipment, served.text)
    cell = {"arms": [
        {"robot": "listed_3r_eq", "waypoints": FOLDING["waypoints"]},
        {"robot": "listed_3r_eq", "base": {"position": [5.0, 0.0, 0.0]}, "waypoints": [[0.0, 0.5, 0.0], [0.5, 0.5, 0.0]]},
    ]}
    answered = client.post("/v1/cells", json=cell)
    assert answered.status_code == 200, answered.text
    plain = {**cell, "arms": [{**arm, "robot": "lecture_3r"} for arm in cell["arms"]]}
    refused = client.post("/v1/cells", json=plain)  # the same cell without the list: the fold is refused
    assert refused.status_code == 422 and "turret" in refused.text and "forearm" in refused.text, refused.text
