#!/usr/bin/env bash
# The container stages of CI, called by .ci/run (run it alone as `bash .ci/container.sh`, as root).
#
#   1. a private Docker engine and a local Debian base image
#   2. the image's two targets: `runtime` (no browser; `docker run … which chromium` must fail)
#      and `test` (runtime plus chromium), then the test suite inside the test image
#   3. smoke check: the runtime image's default command serves /health and the HEALTHCHECK passes
#
# It starts its own dockerd (private socket, exec root and data root, no bridge, no iptables)
# and builds a local Debian base image with debootstrap, since no image registry is assumed to
# be reachable. The base tarball is cached in .ci-work/cache/; everything else is removed on exit.
#
# CI_PYTEST_ARGS: arguments for pytest in the test image (default: none, the whole suite), e.g.
#   CI_PYTEST_ARGS="tests/service/test_web_page.py -n 0" bash .ci/container.sh
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

WORK="$ROOT/.ci-work"
CACHE="$WORK/cache"
DATA_ROOT="$WORK/docker-data"
TMP_ROOT="$WORK/tmp"
# Unix socket paths are limited to ~108 bytes, and containerd puts its sockets under the exec
# root: keep those under a short path of their own.
RUN_DIR=""
EXEC_ROOT=""
PIDFILE=""
IMAGE="toptraj:ci"
TEST_IMAGE="toptraj:ci-test"
SMOKE_NAME="toptraj-ci-smoke-$$"
DEBIAN_SUITE="bookworm"
BASE_INCLUDE="ca-certificates,python3,python3-pip,python3-venv,python-is-python3"
SYSTEM_PATH="/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"
read -r -a PYTEST_ARGS <<<"${CI_PYTEST_ARGS:-}"

export DEBIAN_FRONTEND=noninteractive
export DOCKER_BUILDKIT=0   # the legacy builder only; the Dockerfile needs no BuildKit feature

T_START=$SECONDS
TIMINGS=()

section() {
    printf '\n======================================================================\n'
    printf '== %s\n' "$*"
    printf '======================================================================\n'
}
note() { printf -- '-- %s\n' "$*"; }
die() { printf 'ERROR: %s\n' "$*" >&2; exit 1; }
stage_done() { # name start
    local dt=$((SECONDS - $2))
    TIMINGS+=("$(printf '%-34s %4ds' "$1" "$dt")")
    note "$1: done in ${dt}s"
}

# --------------------------------------------------------------------------- cleanup
mounts_under() { # prints mount points under $1, deepest first
    local prefix="$1" mnt rest
    [ -n "$prefix" ] || return 0
    while read -r _ mnt rest; do
        mnt="$(printf '%b' "$mnt")"
        case "$mnt" in "$prefix"|"$prefix"/*) printf '%s\n' "$mnt" ;; esac
    done </proc/self/mounts | sort -r
}

unmount_under() {
    local m
    mounts_under "$1" | while IFS= read -r m; do
        umount "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || true
    done
}

alive() { # pid: running and not a zombie
    [ -n "$1" ] && [ -r "/proc/$1/status" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status" 2>/dev/null
}

stop_pid() { # pid [seconds]
    local pid="$1" wait_s="${2:-30}" i
    alive "$pid" || return 0
    kill -TERM "$pid" 2>/dev/null || true
    for ((i = 0; i < wait_s * 5; i++)); do
        alive "$pid" || return 0
        sleep 0.2
    done
    note "pid $pid did not stop after ${wait_s}s, killing it"
    kill -KILL "$pid" 2>/dev/null || true
    sleep 0.5
}

cleanup() {
    local rc=$?
    set +e
    trap - EXIT INT TERM
    if [ -n "$PIDFILE" ] && [ -s "$PIDFILE" ]; then
        section "Cleanup"
        if docker info >/dev/null 2>&1; then
            docker rm -f "$SMOKE_NAME" >/dev/null 2>&1
        fi
        local dpid cpid=""
        dpid="$(cat "$PIDFILE")"
        [ -s "$EXEC_ROOT/containerd/containerd.pid" ] && cpid="$(cat "$EXEC_ROOT/containerd/containerd.pid")"
        note "stopping dockerd (pid $dpid)"
        stop_pid "$dpid" 30
        # dockerd stops the containerd it started; make sure of it if dockerd had to be killed.
        [ -n "$cpid" ] && stop_pid "$cpid" 10
    fi
    if [ -n "$EXEC_ROOT" ] && mountpoint -q "$EXEC_ROOT/netns/default" 2>/dev/null; then
        umount "$EXEC_ROOT/netns/default" 2>/dev/null || umount -l "$EXEC_ROOT/netns/default"
    fi
    unmount_under "$RUN_DIR"
    unmount_under "$DATA_ROOT"
    unmount_under "$TMP_ROOT"
    local leftover=""
    for d in "$RUN_DIR" "$DATA_ROOT" "$TMP_ROOT"; do
        [ -n "$d" ] || continue
        if [ -n "$(mounts_under "$d")" ]; then
            leftover="$leftover $d"
        else
            rm -rf "$d"
        fi
    done
    [ -n "$leftover" ] && printf 'WARNING: mounts remain under:%s (not removed)\n' "$leftover" >&2
    if ((${#TIMINGS[@]})); then
        section "Summary"
        printf '%s\n' "${TIMINGS[@]}"
        printf '%-34s %4ds\n' "total" $((SECONDS - T_START))
    fi
    if [ "$rc" -eq 0 ]; then
        printf '\ncontainer stages: all passed\n'
    else
        printf '\ncontainer stages: FAILED (exit %s)\n' "$rc" >&2
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# --------------------------------------------------------------------------- 1. engine and base
section "Container 1/3: engine and base image"
[ "$(id -u)" -eq 0 ] || die "the container stages need root (dockerd, debootstrap)"

t=$SECONDS
need_pkgs=()
command -v dockerd >/dev/null 2>&1 || need_pkgs+=(docker.io)
command -v debootstrap >/dev/null 2>&1 || need_pkgs+=(debootstrap)
if ((${#need_pkgs[@]})); then
    note "installing ${need_pkgs[*]} with apt"
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null
fi
command -v docker >/dev/null 2>&1 || die "no docker client after installing docker.io"
stage_done "tools (docker.io, debootstrap)" "$t"

# ---- engine
t=$SECONDS
mkdir -p "$WORK" "$CACHE" "$TMP_ROOT"
RUN_DIR="$(mktemp -d /tmp/toptraj-ci.XXXXXX)"
EXEC_ROOT="$RUN_DIR/exec"
PIDFILE="$RUN_DIR/dockerd.pid"
DOCKERD_LOG="$WORK/dockerd.log"
export DOCKER_HOST="unix://$RUN_DIR/docker.sock"
note "starting dockerd on $DOCKER_HOST (data root $DATA_ROOT, log $DOCKERD_LOG)"
dockerd \
    --host "$DOCKER_HOST" \
    --data-root "$DATA_ROOT" \
    --exec-root "$EXEC_ROOT" \
    --pidfile "$PIDFILE" \
    --iptables=false --ip6tables=false --bridge=none \
    </dev/null >"$DOCKERD_LOG" 2>&1 &
dockerd_pid=$!
for ((i = 0; ; i++)); do
    if docker info >/dev/null 2>&1; then break; fi
    if ! alive "$dockerd_pid"; then
        tail -n 40 "$DOCKERD_LOG" >&2
        die "dockerd exited during start-up"
    fi
    if ((i >= 120)); then
        tail -n 40 "$DOCKERD_LOG" >&2
        die "dockerd did not answer within 60s"
    fi
    sleep 0.5
done
# the pid file is what cleanup uses; make sure it exists even if dockerd was slow to write it
[ -s "$PIDFILE" ] || echo "$dockerd_pid" >"$PIDFILE"
docker version --format 'engine {{.Server.Version}}, client {{.Client.Version}}'
docker info --format 'storage driver: {{.Driver}}'
stage_done "engine up" "$t"

# ---- base image
# The Debian mirror comes from this machine's apt sources (deb822 files or one-line lists).
debian_mirror() {
    python3 - "$DEBIAN_SUITE" <<'PY'
import glob, re, sys

suite = sys.argv[1]
ok = re.compile(r"^(https?|file)://", re.I)

def one_line(path):
    for line in open(path, encoding="utf-8", errors="replace"):
        line = line.split("#", 1)[0].strip()
        if not line.startswith("deb "):
            continue
        line = re.sub(r"\[[^]]*\]", " ", line)
        parts = line.split()
        if len(parts) >= 3 and parts[2] == suite and ok.match(parts[1]):
            yield parts[1]

def deb822(path):
    text = open(path, encoding="utf-8", errors="replace").read()
    for stanza in re.split(r"\n\s*\n", text):
        fields, key = {}, None
        for line in stanza.splitlines():
            if line.startswith("#"):
                continue
            if line[:1] in (" ", "\t") and key:
                fields[key] += " " + line.strip()
                continue
            if ":" in line:
                key, _, value = line.partition(":")
                key = key.strip().lower()
                fields[key] = value.strip()
        if fields.get("enabled", "yes").lower() == "no":
            continue
        if "deb" not in fields.get("types", "").split():
            continue
        if suite not in fields.get("suites", "").split():
            continue
        for uri in fields.get("uris", "").split():
            if ok.match(uri):
                yield uri

files = ["/etc/apt/sources.list"] + sorted(glob.glob("/etc/apt/sources.list.d/*.list"))
found = []
for path in sorted(glob.glob("/etc/apt/sources.list.d/*.sources")):
    found += list(deb822(path))
for path in files:
    try:
        found += list(one_line(path))
    except OSError:
        pass
if not found:
    sys.exit("no apt source for suite %r in /etc/apt/sources.list{,.d/}" % suite)
print(found[0])
PY
}

t=$SECONDS
MIRROR="$(debian_mirror)"
shopt -s nullglob
host_cas=(/usr/local/share/ca-certificates/*.crt)
shopt -u nullglob
# The cache key covers everything baked into the tarball.
base_key="$({
    echo "$DEBIAN_SUITE $BASE_INCLUDE $MIRROR"
    if ((${#host_cas[@]})); then cat "${host_cas[@]}"; fi
} | sha256sum | cut -c1-12)"
BASE_TAR="$CACHE/base-$DEBIAN_SUITE-$base_key.tar"
BASE_TAG="toptraj-ci-base:$DEBIAN_SUITE-$base_key"
if [ -s "$BASE_TAR" ]; then
    note "using cached base tarball $BASE_TAR"
else
    note "debootstrap $DEBIAN_SUITE from the local apt mirror ($MIRROR)"
    rootfs="$TMP_ROOT/rootfs"
    rm -rf "$rootfs"
    if ! debootstrap --variant=minbase --include="$BASE_INCLUDE" \
        "$DEBIAN_SUITE" "$rootfs" "$MIRROR" >"$WORK/debootstrap.log" 2>&1; then
        tail -n 40 "$WORK/debootstrap.log" >&2
        [ -f "$rootfs/debootstrap/debootstrap.log" ] && tail -n 40 "$rootfs/debootstrap/debootstrap.log" >&2
        die "debootstrap failed"
    fi
    unmount_under "$rootfs"
    if ((${#host_cas[@]})); then
        note "adding ${#host_cas[@]} CA certificate(s) from /usr/local/share/ca-certificates"
        cp "${host_cas[@]}" "$rootfs/usr/local/share/ca-certificates/"
    fi
    chroot "$rootfs" /usr/sbin/update-ca-certificates >/dev/null
    rm -f "$rootfs"/usr/lib/python3*/EXTERNALLY-MANAGED
    rm -rf "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/lib/apt/lists/*
    rm -f "$CACHE"/base-*.tar   # older keys
    tar -C "$rootfs" -cf "$BASE_TAR.part" .
    mv "$BASE_TAR.part" "$BASE_TAR"
    rm -rf "$rootfs"
fi
docker import \
    --change "ENV PATH=$SYSTEM_PATH" \
    --change "ENV LANG=C.UTF-8" \
    --change 'CMD ["python3"]' \
    "$BASE_TAR" "$BASE_TAG" >/dev/null
note "base image $BASE_TAG ($(docker run --rm --network none "$BASE_TAG" python3 --version))"
stage_done "base image" "$t"

# --------------------------------------------------------------------------- 2. images and tests
section "Container 2/3: the runtime and test images, the test suite in the test image"
# The legacy builder builds every stage up to its target: the test target builds the runtime
# stage first, and the runtime build then comes from the cache.
t=$SECONDS
docker build --network host --build-arg BASE_IMAGE="$BASE_TAG" --target test -t "$TEST_IMAGE" .
docker build --network host --build-arg BASE_IMAGE="$BASE_TAG" --target runtime -t "$IMAGE" .
stage_done "docker build (test, runtime)" "$t"

# ---- the runtime image carries no browser
# `which` exits 1 when it finds nothing; any other failure means the look did not happen.
set +e
docker run --network none --rm "$IMAGE" which chromium
found=$?
set -e
case "$found" in
    0) die "the runtime image holds chromium: the browser belongs in the test stage only" ;;
    1) note "runtime image: no chromium (which chromium exits 1)" ;;
    *) die "could not look for chromium in the runtime image (exit $found)" ;;
esac
docker run --network none --rm "$TEST_IMAGE" which chromium

# ---- tests inside the test image
t=$SECONDS
# pyproject's addopts already has -q; a second -q would hide the "N passed" line.
note "docker run $TEST_IMAGE python -m pytest ${PYTEST_ARGS[*]}"
docker run --network host --rm "$TEST_IMAGE" python -m pytest "${PYTEST_ARGS[@]}"
stage_done "tests in the test image" "$t"

# --------------------------------------------------------------------------- 3. smoke
section "Container 3/3: smoke check of the runtime image: default command serves /health, HEALTHCHECK turns healthy"
t=$SECONDS
# Own network namespace (loopback only): the default CMD binds port 8000 there, whatever the
# host is running, and the image's HEALTHCHECK probes it. A short interval makes it quick.
docker run -d --name "$SMOKE_NAME" --network none \
    --health-interval 2s --health-start-period 60s "$IMAGE" >/dev/null
status=""
for ((i = 0; i < 60; i++)); do
    status="$(docker inspect -f '{{.State.Status}} {{if .State.Health}}{{.State.Health.Status}}{{end}}' "$SMOKE_NAME")"
    case "$status" in
        "running healthy") break ;;
        running*) sleep 2 ;;
        *) break ;;
    esac
done
if [ "$status" != "running healthy" ]; then
    docker logs "$SMOKE_NAME" 2>&1 | tail -n 40 >&2
    docker inspect -f '{{json .State.Health}}' "$SMOKE_NAME" >&2 || true
    die "container not healthy (state: ${status:-unknown})"
fi
note "container healthy; GET /health:"
docker exec "$SMOKE_NAME" python -c \
    "import urllib.request; print(urllib.request.urlopen('http://127.0.0.1:8000/health', timeout=5).read().decode())"
docker rm -f "$SMOKE_NAME" >/dev/null
stage_done "smoke check" "$t"
