"""One import name (issue 34): what pip installs adds ``toptraj`` alone, and the installed
package works without the repository on the path (package data read through its own name)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile

from tests.paths import ROOT

CHECK = """
import importlib.util, toptraj, toptraj.client, toptraj.service.app
from toptraj import robots
arm = robots.load("ur5")
from toptraj.robots.catalog import catalog_names
assert arm.dof == 6 and len(catalog_names()) >= 3 and robots.load("geering_2r").dof == 2
for old in ("planners", "robots", "service", "client", "compiled"):
    assert importlib.util.find_spec(old) is None, old
print("ok", toptraj.__version__)
"""


def test_the_installed_package_works_from_anywhere_and_the_old_names_are_gone(tmp_path):
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    done = subprocess.run(
        [sys.executable, "-P", "-c", CHECK], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0 and done.stdout.startswith("ok"), done.stderr[-2000:]


def test_the_wheel_holds_toptraj_alone(tmp_path):
    source = tmp_path / "source"  # a copy: the build writes beside its sources
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    for part in ("toptraj", "robots", "planners", "service", "client", "compiled"):
        shutil.copytree(ROOT / part, source / part, symlinks=True, ignore=skip)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(source)],
        check=True, capture_output=True, timeout=600,
    )
    (wheel,) = tmp_path.glob("toptraj-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert {name.split("/")[0] for name in names} == {"toptraj", "-".join(wheel.name.split("-")[:2]) + ".dist-info"}
    assert "toptraj/robots/urdf/geering_2r.urdf" in names and "toptraj/service/web/static/app.js" in names
