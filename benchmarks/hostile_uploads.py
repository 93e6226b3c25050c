"""How long a hostile `joint_limits` upload takes to be refused, through the whole HTTP stack
(``POST /v1/robots`` with ur5's URDF): YAML alias bombs, deep nesting, a huge integer, keys of
mixed types, and the largest text the bounds accept.

    python benchmarks/hostile_uploads.py

Prints one line per case: the status, the time and the start of the detail. Before the bounded
loader (``robots/bounded_yaml.py``) the depth-8 bomb froze a process for 27 s and the others were
500s; ``tests/robots/test_hostile_uploads.py`` asserts the statuses.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from fastapi.testclient import TestClient

from toptraj.robots.catalog import example_urdf_path
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

UR5 = Path(example_urdf_path("ur5")).read_text()


def bomb(depth: int, width: int = 10) -> str:
    """A YAML alias bomb: each anchor a list of ``width`` aliases of the one before."""
    lines = ["a0: &a0 [1.0]"] + [f"a{k}: &a{k} [{', '.join([f'*a{k - 1}'] * width)}]" for k in range(1, depth + 1)]
    return "\n".join(lines) + f"\njoint_limits:\n  elbow_joint:\n    has_velocity_limits: true\n    max_velocity: *a{depth}\n"


def main() -> None:
    with TestClient(create_app(Settings(preload_robots=False, data_dir=tempfile.mkdtemp()))) as client:
        client.post("/v1/robots", json={"name": "warm", "urdf": UR5})
        largest = "joint_limits:\n" + "".join(f"  j{k}: {{has_velocity_limits: true, max_velocity: 1.0}}\n" for k in range(1800))
        cases = [
            (f"alias bomb, depth 8 ({len(bomb(8))} characters)", bomb(8)),
            ("alias bomb, depth 9", bomb(9)),
            ("nesting 5,000 deep", "joint_limits: " + "[" * 5000 + "]" * 5000),
            ("an integer of 401 digits", "joint_limits:\n  elbow_joint: {has_velocity_limits: true, max_velocity: " + "9" * 401 + "}\n"),
            ("keys of mixed types", "joint_limits: {}\n1: 2\n"),
            (f"the largest text accepted in size ({len(largest)} characters)", largest),
        ]
        for name, text in cases:
            began = time.perf_counter()
            answer = client.post("/v1/robots", json={"urdf": UR5, "joint_limits": text})
            print(f"{name}: {answer.status_code} in {time.perf_counter() - began:.3f} s: {answer.json()['detail'][:110]}")


if __name__ == "__main__":
    main()
