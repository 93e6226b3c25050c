# The two commands of the README: `make serve` and `make test`. Both set up .venv on first use.
PYTHON ?= python3
HOST ?= 127.0.0.1
PORT ?= 8000
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: serve test install browser clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

serve: $(STAMP)
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
	rm -rf $(VENV) build *.egg-info
