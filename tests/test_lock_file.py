"""requirements.lock, what `make` and the Dockerfile install: every dependency of
pyproject.toml (the runtime ones and the test extra) pinned there, at a version inside its
range, with hashes."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]


def pinned() -> dict[str, tuple[str, int]]:
    """{canonical name: (version, number of hashes)} of the lock file."""
    text = (ROOT / "requirements.lock").read_text()
    entries = {}
    for block in re.split(r"\n(?=\S)", text):
        match = re.match(r"([A-Za-z0-9_.\-]+)==(\S+)", block)
        if match:
            entries[canonicalize_name(match[1])] = (match[2], block.count("--hash=sha256:"))
    return entries


def test_every_dependency_is_pinned_inside_its_range_with_hashes():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    wanted = [Requirement(line) for line in project["dependencies"] + project["optional-dependencies"]["test"]]
    lock = pinned()
    for requirement in wanted:
        if requirement.marker is not None and not requirement.marker.evaluate({"sys_platform": "linux"}):
            continue
        name = canonicalize_name(requirement.name)
        assert name in lock, f"{requirement.name} is missing from requirements.lock: run `make lock`"
        version, hashes = lock[name]
        assert requirement.specifier.contains(version, prereleases=True), (
            f"requirements.lock pins {requirement.name}=={version}, outside {requirement.specifier}: run `make lock`"
        )
        assert hashes >= 1, requirement.name


def test_make_and_the_image_install_from_the_lock_file():
    makefile = (ROOT / "Makefile").read_text()
    dockerfile = (ROOT / "Dockerfile").read_text()
    assert "--require-hashes -r requirements.lock" in makefile
    assert "--require-hashes -r requirements.lock" in dockerfile
    assert "--no-deps" in makefile and "--no-deps" in dockerfile
