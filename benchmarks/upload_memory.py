"""Memory of a server process over many URDF uploads, and uploads surviving a restart.

Starts ``toptraj serve`` (``python -m toptraj.service.cli serve``) on a free local port with
``TOPTRAJ_DATA_DIR`` set to a fresh temporary directory, uploads ``--uploads`` copies of the UR5
URDF of example-robot-data, each padded with an XML comment to ``--kib`` KiB and distinct, then
reads every upload back (``GET /v1/robots/{name}``, which builds its model), and prints the
server's resident set size (RSS) at each step. Then it stops the server, starts it again on the
same data directory and checks that every upload is listed, described and plannable.

    python benchmarks/upload_memory.py [--uploads 100] [--kib 864] [--extra-links 0]

With ``--extra-links 980`` each model holds about 2,000 frames (about 2 MB), which shows the
bound of the model cache (``TOPTRAJ_UPLOAD_CACHE_SIZE``, 32 by default) rather than the cost of
the request text alone.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import psutil

REPO = Path(__file__).resolve().parents[1]
UR5_WAYPOINTS = [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3]]


def _ur5_urdf() -> str:
    from example_robot_data.robots_loader import ROBOTS
    from example_robot_data.utils import getModelPath

    loader = ROBOTS["ur5"]
    subpath = os.path.join(loader.path, loader.urdf_subpath, loader.urdf_filename)
    return Path(getModelPath(subpath), subpath).read_text()


def padded(urdf: str, index: int, size: int, extra_links: int = 0) -> str:
    """``urdf`` with ``extra_links`` small links fixed to ``tool0`` (each a frame of the model)
    and a comment that makes it ``size`` characters long and unique to ``index``."""
    links = "".join(
        f'<link name="pad_{k}"><visual><geometry><box size="0.01 0.01 0.01"/></geometry></visual></link>'
        f'<joint name="pad_joint_{k}" type="fixed"><parent link="tool0"/><child link="pad_{k}"/>'
        f'<origin xyz="0 0 {0.001 * k:.3f}"/></joint>\n'
        for k in range(extra_links)
    )
    head, tail = f"<!-- upload {index}: ", " -->\n</robot>"
    body = urdf[: urdf.rindex("</robot>")] + links
    filler = size - len(body) - len(head) - len(tail)
    return body + head + (f"{index:08d} " * (filler // 9 + 1))[:filler] + tail


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _start(data_dir: Path, port: int) -> subprocess.Popen:
    env = {**os.environ, "TOPTRAJ_DATA_DIR": str(data_dir), "PYTHONPATH": str(REPO)}
    process = subprocess.Popen(
        [sys.executable, "-m", "toptraj.service.cli", "serve", "--port", str(port), "--workers", "1"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline:
        try:
            if httpx.get(f"http://127.0.0.1:{port}/health", timeout=1).status_code == 200:
                return process
        except httpx.TransportError:
            time.sleep(0.3)
    process.kill()
    raise SystemExit("the server did not start")


def _rss_mb(process: subprocess.Popen) -> float:
    return psutil.Process(process.pid).memory_info().rss / 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--uploads", type=int, default=100)
    parser.add_argument("--kib", type=int, default=864, help="size of each upload in KiB")
    parser.add_argument(
        "--extra-links", type=int, default=0, help="small fixed links added to each upload (model frames; at most 980)"
    )
    args = parser.parse_args()
    urdf, size = _ur5_urdf(), args.kib * 1024
    data_dir = Path(tempfile.mkdtemp(prefix="toptraj-upload-memory-"))
    port = _free_port()
    server = _start(data_dir, port)
    figures = {}
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120) as client:
            figures["rss_started_mb"] = _rss_mb(server)
            names = []
            for index in range(args.uploads):
                response = client.post("/v1/robots", json={"urdf": padded(urdf, index, size, args.extra_links)})
                if response.status_code != 201:
                    raise SystemExit(f"upload {index}: {response.status_code} {response.text[:500]}")
                names.append(response.json()["name"])
                if index == 0:
                    figures["rss_after_1_upload_mb"] = _rss_mb(server)
            figures[f"rss_after_{args.uploads}_uploads_mb"] = _rss_mb(server)
            for name in names:
                client.get(f"/v1/robots/{name}").raise_for_status()
            figures[f"rss_after_reading_all_{args.uploads}_mb"] = _rss_mb(server)
        figures["store_file_mb"] = sum(path.stat().st_size for path in data_dir.iterdir()) / 1e6
        server.terminate()
        server.wait(timeout=30)
        server = _start(data_dir, port)
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120) as client:
            listed = {row["name"] for row in client.get("/v1/robots").json() if row["source"] == "upload"}
            described = sum(client.get(f"/v1/robots/{name}").status_code == 200 for name in names)
            planned = client.post("/v1/trajectories", json={"robot": names[-1], "path": {"waypoints": UR5_WAYPOINTS}})
            figures["after_restart"] = {
                "listed": len(listed & set(names)),
                "described": described,
                "plan_status": planned.status_code,
                "of": len(names),
            }
            figures["rss_after_restart_and_reading_all_mb"] = _rss_mb(server)
        print(json.dumps({"uploads": args.uploads, "upload_bytes": size, "extra_links": args.extra_links, **figures}, indent=2))
    finally:
        server.terminate()
        server.wait(timeout=30)
        shutil.rmtree(data_dir, ignore_errors=True)


if __name__ == "__main__":
    main()
