# toptraj: time-optimal trajectories over HTTP.
#
#   docker build -t toptraj .
#   docker run --rm -p 8000:8000 toptraj           # serve on :8000
#   docker run --rm -p 8000:8000 -v toptraj-data:/home/toptraj/.local/share/toptraj toptraj
#                                                   # ... keeping uploaded URDFs across containers
#
#   docker build --target test -t toptraj-test .   # the runtime image plus the browser the
#   docker run --rm toptraj-test                    # web page's tests drive: runs the test suite
#
# The runtime stage carries no browser; the `test` stage adds Debian's chromium. Without
# --target the build gives the runtime image (the last stage).
#
# Any Debian-like image with Python >= 3.11 (and the venv module) works as a base:
#   docker build --build-arg BASE_IMAGE=<image> .
ARG BASE_IMAGE=python:3.11-slim
FROM ${BASE_IMAGE} AS runtime

# CA bundle used by pip and Python's ssl module. The default is the system bundle
# of Debian-based images; point it elsewhere when a build needs another one.
ARG CA_BUNDLE=/etc/ssl/certs/ca-certificates.crt

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PIP_CERT=${CA_BUNDLE} \
    SSL_CERT_FILE=${CA_BUNDLE} \
    VIRTUAL_ENV=/opt/venv \
    NUMBA_CACHE_DIR=/opt/numba-cache \
    PATH=/opt/venv/bin:${PATH}

# libgomp1: OpenMP runtime that the pinocchio wheels link against (not bundled in them).
# Unprivileged runtime user; /app is its working directory (pytest keeps its cache there).
# hadolint ignore=DL3008
RUN apt-get update \
    && apt-get install -y --no-install-recommends libgomp1 \
    && rm -rf /var/lib/apt/lists/* \
    && groupadd --gid 10001 toptraj \
    && useradd --create-home --uid 10001 --gid 10001 --shell /usr/sbin/nologin toptraj \
    && python3 -m venv /opt/venv \
    && mkdir /app /opt/numba-cache \
    && chown toptraj:toptraj /app /opt/numba-cache

WORKDIR /app

# Dependencies first, in their own layer: it is rebuilt only when the lock file changes. The
# exact versions and hashes of requirements.lock (the runtime dependencies and the "test"
# extra, so the test suite can run in the image; `make lock` re-resolves it).
COPY requirements.lock ./
RUN pip install --require-hashes -r requirements.lock

# The code (and tests/), the documentation site served at /guide/ (built from docs/ into
# service/web/guide, shipped with the package), then the package itself without touching the
# dependencies.
COPY . .
RUN NO_MKDOCS_2_WARNING=1 python -m mkdocs build --strict --quiet -d service/web/guide \
    && pip install --no-deps . \
    && pip check \
    && rm -rf build ./*.egg-info

USER 10001:10001

# The compiled kernels (numba) in the image, a line per step: two server processes compiling
# them at start took 88 s before /health answered; with the cache in the image, seconds. (-P:
# the installed package, which the server imports, not /app: numba keys its cache by source
# file.)
RUN python -P -m toptraj.service.warmup

EXPOSE 8000

HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 \
    CMD ["python", "-c", "import sys, urllib.request; sys.exit(0 if urllib.request.urlopen('http://127.0.0.1:8000/health', timeout=4).status == 200 else 1)"]

CMD ["toptraj", "serve", "--host", "0.0.0.0", "--port", "8000"]

# ---------------------------------------------------------------------------------- test
# The runtime image plus the real browser the web page's tests drive: Debian's chromium, and
# libatomic1 for the node driver that Playwright bundles.
FROM runtime AS test
USER 0
# hadolint ignore=DL3008
RUN apt-get update \
    && apt-get install -y --no-install-recommends chromium libatomic1 \
    && rm -rf /var/lib/apt/lists/*
USER 10001:10001
# The tests, and the servers they start, import the package from /app rather than the installed
# one: its kernels go into numba's cache too (keyed by source file), so that a test's first
# request does not compile them within its time budget.
RUN python -m toptraj.service.warmup
CMD ["python", "-m", "pytest"]

# ---------------------------------------------------------------------------------- default
# The runtime image, the target of a build without --target.
FROM runtime
