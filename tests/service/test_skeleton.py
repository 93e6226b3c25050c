"""``POST /v1/robots/{name}/skeleton``: joint origins and the end effector in the world, here
against the planar geometry of Jeong & Lee's arm (l1 = 0.4 m, l2 = 0.25 m, ``000_…txt``)."""

from __future__ import annotations

import numpy as np
import pytest

L1, L2 = 0.4, 0.25


@pytest.mark.parametrize("q", [[0.0, 0.0], [np.pi / 2, np.pi / 2], [0.3, -2.0], [-1.0, 6.0]])
def test_the_planar_arm_is_where_its_geometry_puts_it(client, q):
    response = client.post("/v1/robots/geering_2r/skeleton", json={"q": [q]})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["points"] == ["phi", "psi", "hand"]
    phi, psi = q
    elbow = L1 * np.array([np.cos(phi), np.sin(phi)])
    hand = elbow + L2 * np.array([np.cos(phi + psi), np.sin(phi + psi)])
    np.testing.assert_allclose(np.array(body["positions"][0]), [[0, 0, 0], [*elbow, 0], [*hand, 0]], atol=1e-12)


def test_rows_of_the_wrong_length_are_a_422(client):
    response = client.post("/v1/robots/ur5/skeleton", json={"q": [[0.0] * 6, [0.0] * 5]})
    assert response.status_code == 422 and response.json()["detail"].startswith("q[1] holds 5 values; each row of q must hold 6, one per joint")
    assert client.post("/v1/robots/nope/skeleton", json={"q": [[0.0]]}).status_code == 404
