"""Every example's answer, for comparing two commits: ``python docs/measures/answers.py OUT_DIR``
writes OUT_DIR/<example>.json (the answer without its timings); ``python docs/measures/answers.py
--compare A B`` prints, per example, whether the answers are bit-identical, else the largest
relative difference of their numbers and the fields that differ.

Run from the repository root with the commit's tree first on the path (``PYTHONPATH=$PWD``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: Fields that measure the run, not the answer (and every field ending in ``_s``: seconds taken).
TIMINGS = {"solve_ms"}


def _without_timings(value):
    if isinstance(value, dict):
        return {key: _without_timings(item) for key, item in value.items() if key not in TIMINGS and not key.endswith("_s")}
    if isinstance(value, list):
        return [_without_timings(item) for item in value]
    return value


def write(out: Path) -> None:
    from fastapi.testclient import TestClient

    from toptraj.service.app import create_app
    from toptraj.service.settings import Settings

    out.mkdir(parents=True, exist_ok=True)
    with TestClient(create_app(Settings(plan_budget_s=600.0))) as client:
        for example in sorted((ROOT / "examples").glob("*.json")):
            body = json.loads(example.read_text())
            route = "/v1/trajectories/compare" if "methods" in body else "/v1/trajectories"
            response = client.post(route, json=body)
            answer = {"status": response.status_code, "body": _without_timings(response.json())}
            (out / example.name).write_text(json.dumps(answer, sort_keys=True))
            print(example.name, response.status_code, flush=True)


def _differences(a, b, path: str = "") -> tuple[float, list[str]]:
    """Largest relative difference of the numbers of ``a`` and ``b`` and the paths that differ
    otherwise (keys, lengths, strings)."""
    if isinstance(a, dict) and isinstance(b, dict):
        worst, where = 0.0, [f"{path}.{key}" for key in set(a) ^ set(b)]
        for key in set(a) & set(b):
            w, p = _differences(a[key], b[key], f"{path}.{key}")
            worst, where = max(worst, w), where + p
        return worst, where
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return 0.0, [f"{path}: {len(a)} != {len(b)} items"]
        worst, where = 0.0, []
        for k, (x, y) in enumerate(zip(a, b)):
            w, p = _differences(x, y, f"{path}[{k}]")
            worst, where = max(worst, w), where + p
        return worst, where
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if a == b:
            return 0.0, []
        return abs(a - b) / max(abs(a), abs(b), 1e-300), []
    return (0.0, []) if a == b else (0.0, [f"{path}: {str(a)[:80]!r} != {str(b)[:80]!r}"])


def compare(a: Path, b: Path) -> None:
    for example in sorted(a.glob("*.json")):
        left, right = json.loads(example.read_text()), json.loads((b / example.name).read_text())
        if left == right:
            print(f"{example.name}: bit-identical")
            continue
        worst, where = _differences(left, right)
        print(f"{example.name}: largest relative difference {worst:.3g}; other differences: {where[:5]}")


if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        compare(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        write(Path(sys.argv[1]))
