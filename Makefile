# The two commands of the README: `make serve` and `make test`. Both set up .venv on first use.
# `make guide` builds the documentation site (docs/, mkdocs.yml) that the service serves at /guide/.
PYTHON ?= python3
HOST ?= 127.0.0.1
PORT ?= 8000
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: serve test install guide browser lock clean

GUIDE := service/web/guide
GUIDE_SOURCES := mkdocs.yml $(shell find docs compiled robots planners client -name '*.md' -o -name '*.py' -o -name '*.png' 2>/dev/null)

# Exact versions with their hashes from requirements.lock (the runtime dependencies and the
# test extra, resolved from the ranges in pyproject.toml), then the project itself on top;
# pip check fails when the lock no longer holds a dependency pyproject.toml asks for (make lock).
# Last, the compiled kernels into numba's cache (a line per step; a minute or more on two
# cores), so that the first `make serve` is ready in seconds rather than compiling them.
$(STAMP): pyproject.toml requirements.lock
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	@echo "toptraj install: the locked dependencies into $(VENV) (about 2.6 GB; a minute or more) ..."
	$(BIN)/python -m pip install --quiet --require-hashes -r requirements.lock
	$(BIN)/python -m pip install --quiet --no-deps -e .
	$(BIN)/python -m pip check
	$(BIN)/python -m toptraj.service.warmup
	touch $(STAMP)

# Re-resolve requirements.lock after a change of the ranges in pyproject.toml (uv's resolver,
# for Linux x86_64 and Python 3.11, the platform of the image and of CI).
lock: $(STAMP)
	$(BIN)/python -m pip install --quiet uv
	$(BIN)/uv pip compile pyproject.toml --extra test --python-version 3.11 \
	  --python-platform x86_64-manylinux_2_28 --generate-hashes --quiet -o requirements.lock

install: $(STAMP) guide

# The site, offline (no web fonts, no CDN), with the library's reference from its docstrings;
# --strict: a broken link, anchor or reference fails the build.
guide: $(GUIDE)/index.html

$(GUIDE)/index.html: $(STAMP) $(GUIDE_SOURCES)
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict --quiet -d $(GUIDE)

serve: $(STAMP) guide
	$(BIN)/toptraj serve --host $(HOST) --port $(PORT)

# The web page's tests drive a real browser: Debian's chromium, installed with apt when missing
# (as root; otherwise install it yourself).
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	  { [ "$$(id -u)" = 0 ] && { apt-get install -y -qq chromium >/dev/null 2>&1 || \
	    { apt-get update -qq && apt-get install -y -qq chromium >/dev/null; }; }; } || \
	  echo "chromium is missing and cannot be installed here: apt-get install chromium"

test: $(STAMP) browser
	$(BIN)/python -m pytest

clean:
	rm -rf $(VENV) build *.egg-info $(GUIDE)
