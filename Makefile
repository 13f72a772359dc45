# The two set-up commands: `make demo` and `make test`. Both create .venv when missing.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check -q

.PHONY: demo test test-slow lint format sysdeps clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PIP) install -U pip

# open3d (the `vision` extra) needs libusb-1.0 at import time; install it when missing and we are root.
sysdeps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then \
	  if [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null; then \
	    echo "installing libusb-1.0-0 (needed by open3d)"; \
	    (apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1 || \
	     (apt-get update -qq >/dev/null && apt-get install -y -qq libusb-1.0-0 >/dev/null)) || \
	     echo "warning: could not install libusb-1.0-0; open3d features will be unavailable"; \
	  else echo "note: libusb-1.0-0 missing and not root; open3d features will be unavailable"; fi; \
	fi

$(VENV)/.installed-demo: pyproject.toml | $(PY)
	$(PIP) install -e '.[sim,vision]'
	@touch $@

# the test environment includes Ray (`dist`) so the Ray backends of the runner and the generator are tested
$(VENV)/.installed-test: pyproject.toml Makefile | $(PY)
	$(PIP) install -e '.[dev,sim,vision,serve,llm,dist,fast]'
	@touch $@ $(VENV)/.installed-demo

# perceives from RGB-D alone with the shipped detector (`gsr demo --oracle-masks`: the simulator's labelled masks)
demo: sysdeps $(VENV)/.installed-demo
	$(VENV)/bin/gsr demo

test: sysdeps $(VENV)/.installed-test
	$(VENV)/bin/ruff check .
	$(PY) -m pytest -n 2 -rs

test-slow: $(VENV)/.installed-test
	$(PY) -m pytest -n 2 -m 'slow or physics'

lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

format: $(VENV)/.installed-test
	$(VENV)/bin/ruff format .
	$(VENV)/bin/ruff check --fix .

clean:
	rm -rf $(VENV) build dist *.egg-info out
