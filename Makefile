# jointquake — two commands: `make demo` and `make test` (see README.md).
#
# gmsh and meshio come from PyPI into a project-local .venv (created on first use).
# GMSH=/path/to/gmsh overrides the gmsh executable. SCENE=pipelines/x.json for mesh/run.

SHELL := /bin/bash
VENV      := .venv
PY        := $(VENV)/bin/python
GMSH_RUN  := $(CURDIR)/$(VENV)/bin/gmsh-run
GMSH      ?= $(GMSH_RUN)
export GMSH
BIN       := target/release/jointquake
SCENE     ?= pipelines/demo.json
# Shared libraries the gmsh wheel links (Debian package names).
GMSH_DEBS := libglu1-mesa libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 libx11-6 libgl1

.PHONY: demo test venv build mesh run bench clean fixtures

# ---- set-up -------------------------------------------------------------------------
$(VENV)/.ready:
	@command -v python3 >/dev/null || { echo "make: python3 is needed (apt-get install python3 python3-venv)"; exit 1; }
	@test -x $(PY) || python3 -m venv $(VENV) || { echo "make: cannot create $(VENV): apt-get install python3-venv"; exit 1; }
	$(PY) -m pip install --quiet --disable-pip-version-check gmsh meshio numpy
	@printf '#!/bin/sh\nd=$$(dirname "$$0")\nexec "$$d/python" "$$d/gmsh" "$$@"\n' > $(VENV)/bin/gmsh-run && chmod +x $(VENV)/bin/gmsh-run
	@if ! $(PY) -c "import gmsh" 2>/dev/null; then \
	  echo "make: the gmsh wheel needs X11/GL libraries; installing: $(GMSH_DEBS)"; \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(GMSH_DEBS) >/dev/null) || true; \
	  elif command -v sudo >/dev/null && command -v apt-get >/dev/null; then \
	    (sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(GMSH_DEBS) >/dev/null) || true; \
	  fi; \
	  $(PY) -c "import gmsh" || { echo "make: gmsh still cannot load; install these packages and retry: sudo apt-get install $(GMSH_DEBS)"; exit 1; }; \
	fi
	@touch $@

venv: $(VENV)/.ready

build:
	cargo build --release

# ---- the two commands ----------------------------------------------------------------
demo: venv build
	@$(BIN) run $(SCENE) --out out/demo
	@$(PY) scripts/check_vtu.py out/demo --quiet
	@echo
	@echo "Open out/demo/$$(basename $(SCENE) .json).pvd in ParaView (File > Open, then Apply)."

test: venv
	cargo test --release
	@echo "== gmsh path: mesh a .geo through the CLI and run it"
	cargo build --release
	$(BIN) mesh pipelines/demo.json
	GMSH=$(GMSH) cargo test --release --test all -- --ignored gmsh
	@echo "== meshio cross-check of the demo output"
	$(BIN) run pipelines/demo.json --out target/test-demo --quiet
	$(PY) scripts/check_vtu.py target/test-demo
	@echo "make test: all checks passed"

# ---- stages --------------------------------------------------------------------------
mesh: venv build
	$(BIN) mesh $(SCENE)

run: venv build
	$(BIN) run $(SCENE)

bench: build
	cargo bench --bench explicit
	cargo bench --bench tagger
	cargo bench --bench contact

fixtures: venv
	GMSH=$(GMSH) scripts/fixtures.sh

clean:
	rm -rf target out build
