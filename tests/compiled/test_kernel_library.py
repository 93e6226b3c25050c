"""The library compiled ahead of time (``toptraj.compiled``): ``toptraj plan`` of the typical
request runs from it without importing numba, and answers exactly as numba's kernels do; a
library built from other sources is not used; arguments of other types than it was built for
go to numba, with numba's answer."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig

import numpy as np
import pytest

from tests.paths import ROOT
from toptraj.compiled import arguments, kernel, library
from toptraj.compiled.build import build
from toptraj.service.warmup import TYPICAL, _typical

pytestmark = pytest.mark.skipif(
    shutil.which((sysconfig.get_config_var("CC") or "cc").split()[0]) is None, reason="no C compiler to build the library with"
)

#: Plans the typical request as ``toptraj plan`` does, then says whether numba was imported.
PLAN = """
import sys
from toptraj.service import commands
commands.plan(sys.argv[1])
sys.stdout.flush()
print("numba imported" if "numba" in sys.modules else "numba not imported", file=sys.stderr)
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A library of the typical request's kernels in a folder of its own."""
    folder = tmp_path_factory.mktemp("kernels")
    saved = os.environ.get("TOPTRAJ_KERNEL_LIBRARY")
    os.environ["TOPTRAJ_KERNEL_LIBRARY"] = str(folder)
    try:
        build(_typical)
        yield folder
    finally:
        if saved is None:
            os.environ.pop("TOPTRAJ_KERNEL_LIBRARY", None)
        else:
            os.environ["TOPTRAJ_KERNEL_LIBRARY"] = saved
        kernel.forget_library()


def _plan(request_file, **env):
    done = subprocess.run(
        [sys.executable, "-c", PLAN, str(request_file)],
        cwd=ROOT, env={**os.environ, **env}, capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    answer = json.loads(done.stdout)
    answer.pop("solve_ms", None)
    return answer, done.stderr.strip().splitlines()[-1]


def test_the_typical_request_runs_from_the_library_without_numba_and_answers_as_numba(built, tmp_path):
    request = tmp_path / "typical.json"
    request.write_text(json.dumps(TYPICAL))
    ahead, ahead_numba = _plan(request, TOPTRAJ_KERNEL_LIBRARY=str(built), TOPTRAJ_KERNELS="library")
    jit, jit_numba = _plan(request, TOPTRAJ_KERNEL_LIBRARY=str(built), TOPTRAJ_KERNELS="jit")
    assert (ahead_numba, jit_numba) == ("numba not imported", "numba imported")
    assert ahead == jit  # every number, to the bit (JSON keeps a float's shortest round trip)
    assert len(ahead["samples"]["t"]) > 50


def test_a_library_built_from_other_sources_is_not_used(built, monkeypatch):
    manifest = json.loads((built / f"{library.MODULE}.json").read_text())
    assert library.current(manifest)
    source = next(iter(manifest["sources"]))
    manifest["sources"][source] = "0" * 64
    assert not library.current(manifest)
    stale = built.parent / "stale"
    stale.mkdir(exist_ok=True)
    shutil.copy(built / manifest["library"], stale / manifest["library"])
    (stale / f"{library.MODULE}.json").write_text(json.dumps(manifest))
    monkeypatch.setenv("TOPTRAJ_KERNEL_LIBRARY", str(stale))
    monkeypatch.setenv("TOPTRAJ_KERNELS", "library")
    kernel.forget_library()
    try:
        assert library.functions_of("toptraj.planners.checks.limit_kernels", "utilization_pass") == {}
    finally:
        kernel.forget_library()


def test_arguments_of_other_types_go_to_numba(built, monkeypatch):
    from toptraj.planners.checks.limit_kernels import utilization_pass

    monkeypatch.setenv("TOPTRAJ_KERNEL_LIBRARY", str(built))
    monkeypatch.setenv("TOPTRAJ_KERNELS", "library")
    kernel.forget_library()
    try:
        compiled = library.functions_of("toptraj.planners.checks.limit_kernels", "utilization_pass")
        assert compiled, "the typical request checks its limits through this kernel"
        rng = np.random.default_rng(3)
        values, limits = rng.normal(size=(40, 6)), np.full(6, 1.5)
        for dtype, in_library in ((np.float64, True), (np.float32, False)):  # float32: numba's own
            args = (values.astype(dtype), limits.astype(dtype), 1.0, np.zeros(6), np.zeros(40, dtype=bool))
            expected = (*args[:3], np.zeros(6), np.zeros(40, dtype=bool))
            assert (arguments.key(args) in compiled) == in_library
            result = utilization_pass(*args)
            reference = utilization_pass.py_func(*expected)
            np.testing.assert_array_equal(args[3], expected[3])
            np.testing.assert_array_equal(args[4], expected[4])
            assert result == reference
    finally:
        kernel.forget_library()


def test_the_library_releases_the_interpreter_lock_as_nogil_kernels_do(built):
    """Its functions' CPython wrappers save the thread state (``PyEval_SaveThread``) around the
    call, as numba's ``nogil=True`` wrappers do; pycc's own would hold the lock throughout."""
    manifest = json.loads((built / f"{library.MODULE}.json").read_text())
    assert b"PyEval_SaveThread" in (built / manifest["library"]).read_bytes()


def test_a_truncated_library_file_is_not_loaded(built, tmp_path):
    """Loading maps the file: a cut-off copy would kill the process at its first call (SIGBUS).
    Its SHA-256 differs from the manifest's, so the kernels run from numba instead."""
    manifest = json.loads((built / f"{library.MODULE}.json").read_text())
    cut = tmp_path / "cut"
    cut.mkdir()
    whole = (built / manifest["library"]).read_bytes()
    (cut / manifest["library"]).write_bytes(whole[: len(whole) // 10])
    (cut / f"{library.MODULE}.json").write_text(json.dumps(manifest))
    probe = (
        "from toptraj.compiled import library\n"
        "print(len(library.functions_of('toptraj.planners.checks.limit_kernels', 'utilization_pass')))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], cwd=ROOT, env={**os.environ, "TOPTRAJ_KERNEL_LIBRARY": str(cut), "TOPTRAJ_KERNELS": "library"},
        capture_output=True, text=True, timeout=300,
    )
    assert (done.returncode, done.stdout.strip()) == (0, "0"), done.stderr[-1000:]


def test_without_a_c_compiler_the_install_step_says_so_and_goes_on(monkeypatch, tmp_path):
    from toptraj.service.warmup import _ahead_of_time

    monkeypatch.setenv("TOPTRAJ_KERNEL_LIBRARY", str(tmp_path / "library"))
    monkeypatch.setenv("PATH", str(tmp_path))  # no cc, gcc or ld on it
    try:
        note = _ahead_of_time()
    finally:
        kernel.forget_library()
    assert note is not None and note.startswith("not built, the kernels run from numba's cache: ")
    assert "\n" not in note  # one line of the install's log
    assert not (tmp_path / "library" / f"{library.MODULE}.json").exists()


def test_a_build_records_what_numba_compiles_never_the_librarys_functions():
    """While a build records, every call goes to numba (whose overloads it exports), even for a
    kernel that already holds library functions for those arguments."""
    from toptraj.compiled.kernel import recording
    from toptraj.planners.checks.limit_kernels import utilization_pass

    args = (np.ones((3, 2)), np.full(2, 2.0), 1.0, np.zeros(2), np.zeros(3, dtype=bool))
    used = []
    with recording() as calls:
        utilization_pass._ahead = {arguments.key(args): lambda *given: used.append(given)}
        result = utilization_pass(*args)
    kernel.forget_library()
    assert used == [] and result == (0.5, 0, 0) and calls[-1][0] is utilization_pass
    assert numba_types(args) in utilization_pass.dispatcher.overloads


def test_checkouts_sharing_numba_s_cache_keep_a_library_each(monkeypatch, tmp_path):
    monkeypatch.delenv("TOPTRAJ_KERNEL_LIBRARY", raising=False)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    folders = set()
    for root in (tmp_path / "one" / "toptraj", tmp_path / "two" / "toptraj"):
        monkeypatch.setattr(library, "package_root", lambda root=root: root)
        folders.add(library.folder())
    assert len(folders) == 2 and all(folder.parent == tmp_path for folder in folders)


def numba_types(args):
    import numba

    return tuple(numba.typeof(value) for value in args)


def test_only_one_shot_commands_use_the_library(built, tmp_path):
    """``toptraj plan`` (which sets ``TOPTRAJ_KERNELS=library``) runs from it; the library call a
    server makes does not (its dispatchers are cheaper per call, and its start is paid once)."""
    request = tmp_path / "typical.json"
    request.write_text(json.dumps(TYPICAL))
    env = {key: value for key, value in os.environ.items() if key != "TOPTRAJ_KERNELS"}
    probe = (
        "import sys\nfrom toptraj.service.cli import main\nstatus = main(['plan', sys.argv[1]])\nsys.stdout.flush()\n"
        "print('numba imported' if 'numba' in sys.modules else 'numba not imported', file=sys.stderr)\n"
    )
    server_like = "import sys\nfrom toptraj.service import commands\ncommands.plan(sys.argv[1])\nprint('numba' in sys.modules, file=sys.stderr)\n"
    outcomes = []
    for code in (probe, server_like):
        done = subprocess.run(
            [sys.executable, "-c", code, str(request)], cwd=ROOT, env={**env, "TOPTRAJ_KERNEL_LIBRARY": str(built)},
            capture_output=True, text=True, timeout=600,
        )
        assert done.returncode == 0, done.stderr[-2000:]
        outcomes.append(done.stderr.strip().splitlines()[-1])
    assert outcomes == ["numba not imported", "True"]
