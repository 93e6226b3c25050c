"""A path toppra's grid cannot time while the phase-plane integrator can: the refusal names the
phase-plane duration, and following it gives that answer."""

from __future__ import annotations

import re

import pytest

from tests.service.answer_limits import assert_limits_held

#: z1 blended through two waypoints 5.6e-4 rad apart that turn sharply (4e-4 of the path's
#: length, kept by path.min_spacing): toppra's controllable sets come out empty at the turn
#: ("no motion can follow the path from s = 0.8171 to its end"), with no advice.
SHARP_PAIR = {
    "robot": "z1",
    "path": {"interpolation": "blend", "waypoints": [
        [0.0, 1.483529864195, -1.439896632895, 0.0, 0.0, 0.0],
        [-0.510136802179, 1.969483487615, -1.366050010957, 0.242668393326, -0.219683145881, -0.336471376978],
        [-1.193026500491, 2.239495638584, -1.188840587711, 0.391608713893, -0.086903290152, -0.683737368839],
        [-1.192594299797, 2.239161499354, -1.189084398796, 0.391642872874, -0.086901009969, -0.68363014555],
        [-1.470387022048, 1.945470804132, -0.955132391605, 0.326038273134, 0.237660514239, -0.955064881244],
        [-1.107344978452, 1.466461279525, -0.726730869266, 0.099131215533, 0.361248353338, -1.08268720141],
    ]},
    "timing": {"method": "toppra", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.001},
}


def test_a_toppra_refusal_names_the_phase_plane_duration_that_holds(client):
    refused = client.post("/v1/trajectories", json=SHARP_PAIR)
    assert refused.status_code == 422, refused.text[:300]
    detail = refused.json()["detail"]
    assert detail.startswith("no motion can follow the path from s = 0.8171 to its end")
    stated = re.search(r"the phase_plane method times this path in ([0-9.]+) s", detail)
    assert stated is not None, detail
    body = {**SHARP_PAIR, "timing": {**SHARP_PAIR["timing"], "method": "phase_plane"}}
    followed = client.post("/v1/trajectories", json=body)
    assert followed.status_code == 200, followed.text[:300]
    assert followed.json()["duration"] == pytest.approx(float(stated.group(1)), rel=1e-3)
    assert_limits_held(body, followed.json())


def test_a_refusal_no_timing_escapes_names_no_other_method(client):
    """A duration too short, or a path the torque limits cannot hold still, is refused for what
    it is: no method times it, and none is named."""
    body = {**SHARP_PAIR, "timing": {**SHARP_PAIR["timing"], "limits": {"torque_scale": 0.01}}}
    refused = client.post("/v1/trajectories", json=body)
    assert refused.status_code == 422 and "phase_plane method times" not in refused.json()["detail"]
