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
SCENE     ?= pipelines/wedge.json
STUDY     ?= pipelines/wedge_study.json
# The wedge study file whose kind draws the demo's charts (`study chart`).
WEDGE_STUDY := pipelines/wedge_study.json
# Parallel runs of `make wedge` (independent scenes, one thread each). Default: all cores.
JOBS      ?= $(shell nproc 2>/dev/null || echo 2)
# Shared libraries the gmsh wheel links (Debian package names).
GMSH_DEBS := libglu1-mesa libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 libx11-6 libgl1

.PHONY: demo test venv build mesh run bench clean fixtures fuzz study study-report wedge wedge3 wedge-report incline joint-tests dam-static dam dam-coarse dam-convergence

# ---- set-up -------------------------------------------------------------------------
$(VENV)/.ready:
	@command -v python3 >/dev/null || { echo "make: python3 is needed (apt-get install python3 python3-venv)"; exit 1; }
	@test -x $(PY) || python3 -m venv $(VENV) || { echo "make: cannot create $(VENV): apt-get install python3-venv"; exit 1; }
	$(PY) -m pip install --quiet --disable-pip-version-check gmsh meshio numpy pyrotd
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
	@echo "== limit equilibrium of the seed wedge (Hoek & Bray)"
	@$(BIN) wedge-fs
	@echo
	@echo "== the wedge at 1.0 g (El Centro NS + 2/3 vertical), node-to-segment contact"
	@$(BIN) run pipelines/wedge.json --out out/demo
	@$(BIN) study chart $(WEDGE_STUDY) --scene pipelines/wedge.json --run out/demo
	@$(PY) scripts/check_vtu.py out/demo --quiet
	@echo
	@echo "ParaView: open out/demo/wedge.pvd (the blocks) and out/demo/joints/A.pvd, B.pvd (joint surfaces: gap, slip, state),"
	@echo "          File > Open, then Apply. Histories: out/demo/histories/*.csv. Charts: out/demo/charts/*.png (.svg)."
	@echo "The whole study (PGA sweep, NTS/NTN/rigid, speed against accuracy, report): make wedge"
	@echo "The arch dam study (28 joints at 1x, 2x, 3x the design PGA, NTS against NTN; out/dam/report.md): make dam"

test: venv
	python3 $$(if [ -f ../shared/tools/modcycles.py ]; then echo ../shared/tools/modcycles.py; else echo scripts/modcycles.py; fi) src
	JQ_REQUIRE_VENV=1 cargo test --release
	@echo "== gmsh path: mesh a .geo through the CLI and run it"
	cargo build --release
	$(BIN) mesh pipelines/column.json
	GMSH=$(GMSH) cargo test --release --test all -- --ignored gmsh
	@echo "== meshio cross-check of the column scene"
	rm -rf target/test-column target/test-demo target/test-impact
	$(BIN) run pipelines/column.json --out target/test-column --quiet
	$(PY) scripts/check_vtu.py target/test-column
	@echo "== the demo's wedge scene (first 2 s) and its charts, cross-checked with meshio"
	$(BIN) run pipelines/wedge.json --out target/test-demo --duration 2 --quiet
	$(BIN) study chart $(WEDGE_STUDY) --scene pipelines/wedge.json --run target/test-demo
	$(PY) scripts/check_vtu.py target/test-demo
	@echo "== ParaView itself: the demo's volume and joint series together (one time axis, arrays, one PNG)"
	@if command -v pvpython >/dev/null && command -v xvfb-run >/dev/null; then \
	  scripts/pvrun.sh scripts/check_paraview.py target/test-demo target/test-demo/paraview.png; \
	else \
	  echo "make test: ParaView check SKIPPED: pvpython or xvfb-run not installed (Debian: apt-get install paraview python3-paraview xvfb)"; \
	fi
	@echo "== ParaView itself: the dam study's state (dam.pvsm of the coarse fixture study run by cargo test, tests/all/dam_study.rs) rendered, not blank"
	@if command -v pvpython >/dev/null && command -v xvfb-run >/dev/null; then \
	  scripts/pvrun.sh scripts/render_pvsm.py target/test-scratch/dam_study/small/out/dam.pvsm target/test-scratch/dam_study/small/out/dam.png; \
	else \
	  echo "make test: ParaView render of dam.pvsm SKIPPED: pvpython or xvfb-run not installed (Debian: apt-get install paraview python3-paraview xvfb)"; \
	fi
	@echo "== meshio cross-check of a scene with a joint (joint series, joint history)"
	$(BIN) run pipelines/impact.json --out target/test-impact --quiet
	$(PY) scripts/check_vtu.py target/test-impact
	@echo "== 5 % response spectrum of El Centro NS against pyrotd (1 % at every period)"
	$(PY) -c "import pyrotd" 2>/dev/null || $(PY) -m pip install --quiet --disable-pip-version-check pyrotd
	$(PY) scripts/check_spectrum.py $(BIN) pipelines/records/elcentro1940_NS_chopra.txt target/test-spectrum
	@echo "make test: all checks passed"

# ---- stages --------------------------------------------------------------------------
mesh: venv build
	$(BIN) mesh $(SCENE)

run: venv build
	$(BIN) run $(SCENE)

# Any study (docs/studies.md): plan (scenes, meshes, runs.mk), its runs and steps in parallel
# ($(JOBS) at a time; a run already done with an unchanged scene is not redone), then the
# report (<out>/report.md, report.json, charts/). STUDY=pipelines/x_study.json.
study: venv build
	@mk=$$($(BIN) study plan $(STUDY) --bin $(CURDIR)/$(BIN) | tee /dev/stderr | sed -n 's/^  makefile  //p') && \
	  $(MAKE) --no-print-directory -j$(JOBS) -f $$mk all ALONE_THREADS=$(JOBS)
	$(BIN) study report $(STUDY)

# Only the report, from the runs already done.
study-report: build
	$(BIN) study report $(STUDY)

# The wedge study (docs/wedge.md; out/wedge): 42 runs and the strength reduction.
wedge:
	$(MAKE) --no-print-directory study STUDY=pipelines/wedge_study.json

# The same study with the three-component El Centro 1940 (PEER RSN6: 180 along y, 270 along x,
# UP along z, scaled together) when ../shared/records is present (medium mesh only).
EC3 := ../shared/records/elcentro1940_RSN6_ELC180.txt
wedge3:
	@if [ ! -f $(EC3) ]; then echo "make wedge3: $(EC3) is not here; this study needs the three-component El Centro records"; exit 1; fi
	$(MAKE) --no-print-directory study STUDY=pipelines/wedge_elcentro3_study.json

wedge-report:
	$(MAKE) --no-print-directory study-report STUDY=pipelines/wedge_study.json

# The El Centro incline (docs/studies.md): friction angle 35°/40° × PGA 0.25/0.5/0.75 g on the
# committed incline fixture against the rigid Newmark block (6 runs of about 12 s; out/incline).
# The arch dam (docs/dam.md): mesh geo/arch_dam.geo (defaults), tag the 28 joints and the base,
# the static state with the construction sequence and the modes empty and full, joints bonded.
dam-static: venv build
	$(BIN) tag pipelines/dam.json --out out/dam_static
	$(BIN) modes pipelines/dam.json -n 6 --out out/dam_static/full
	$(BIN) modes pipelines/dam_empty.json -n 6 --out out/dam_static/empty
	$(BIN) dam-static pipelines/dam.json --out out/dam_static
	@echo
	@echo "ParaView: out/dam_static/dam.pvd (the static state: stress, principal_stress, displacement),"
	@echo "          out/dam_static/joints/J01.pvd ... J28.pvd, base.pvd (opening, normal_traction),"
	@echo "          out/dam_static/full/modes/modes.pvd, out/dam_static/empty/modes/modes.pvd (mode shapes)."
	@echo "Table: out/dam_static/static_table.md; tagging: out/dam_static/tagging/; modes: */modes/modes.json."

incline:
	$(MAKE) --no-print-directory study STUDY=pipelines/incline_study.json

# The joint-test matrix (docs/validation.md §8): generated mismatched-mesh cases (patch, slide,
# newmark, impact; `jointquake testcase`) against their exact references, one line each in
# pipelines/joint_tests_study.json; out/joint-tests/report.md (about 1 min on 2 cores).
joint-tests:
	$(MAKE) --no-print-directory study STUDY=pipelines/joint_tests_study.json

# A study on a real single-node Slurm (docs/cluster.md): installs slurm-wlm and munge if missing
# (as root), starts slurmctld and slurmd on this machine, runs the incline study (shortened) on it
# and locally, compares the reports, kills one array task and re-submits; stops the daemons.
# Status 3 when Slurm cannot be started here (SLURM_CANNOT_START_OK=1: prints SKIPPED, status 0).
.PHONY: test-slurm
test-slurm: build
	scripts/slurm/test.sh

# The arch dam study (docs/dam.md, "Seismic study"; out/dam/report.md): 28 contraction joints at
# 1x, 2x, 3x the design PGA, NTS and NTN; the coarse mesh, the monolithic dam and NTS-Layer2 at
# 3x, mortar at 1x and 3x, the reservoir and foundation models. Each run prints its start and
# end; a failed run is named in the report. The fine mesh is in `make dam-convergence`; the
# verdicts read its extrapolated reference, pipelines/dam_reference.json (docs/dam.md, "Budget").
dam:
	$(MAKE) --no-print-directory study STUDY=pipelines/dam_study.json
	@echo
	@echo "ParaView: paraview --state out/dam/dam.pvsm (run nts-default-3x, a frame every 0.05 s: the dam warped and coloured by |u|, the rock hidden, the joints by opening)"

dam-coarse:
	$(MAKE) --no-print-directory study STUDY=pipelines/dam_coarse_study.json
	@echo
	@echo "ParaView: paraview --state out/dam_coarse_study/dam.pvsm (run nts-coarse-3x, a frame every 0.05 s)"

# Mesh convergence of the dam study (docs/dam.md, "Convergence"): NTS and NTN at 1x and 3x on
# the coarse, default, fine and h 2.5 m meshes (16 runs), then the extrapolated reference
# pipelines/dam_reference.json that `make dam`'s report reads. Not run whole here: each h 2.5 m
# NTS run takes about 1 h 10 min on 2 threads of a quiet machine and 12.8 GB (74 322 steps; NTS at
# 3x measured: 828 s static, 3386 s dynamic; docs/dam.md, "The h 2.5 m runs"); each NTN one about
# 1 h 5 min and 12.6 GB (NTN 1x measured: 1 h 3 min 32 s, 972 s static, 2831 s dynamic; NTN's
# Newton needs 2x NTS's iterations: docs/performance.md, "NTN's static state"). The whole
# target is about 5 h 15 min on 2 cores (docs/dam.md, "Convergence"); the h 2.5 m static states
# have since become 4.4 min (NTS) and 1.9 min (NTN) shorter, so about 5 h now (not rerun). The
# h 2.5 m mesh is `alone` in the study file: its four runs go first, one at a time on $(JOBS)
# threads, the twelve others after them (two h 2.5 m runs at once would need 25 GB;
# docs/studies.md, `alone`). The NTS runs hold their re-entry penetrations (`reentry: "hold"`):
# pushed out, they stopped the h 2.5 m NTS 3x run at t = 4.24 s (docs/contact.md, "Re-entry").
# DAM_CONVERGENCE=pipelines/dam_convergence_affordable_study.json: coarse and default only
# (8 runs, about 18 CPU-minutes). DAM_CONVERGENCE=pipelines/dam_convergence_three_study.json:
# coarse, default and fine (12 runs; the fine ones 15-18 min each on one core, about 67 min with
# JOBS=2; the committed reference's runs, docs/dam.md "Convergence").
DAM_CONVERGENCE ?= pipelines/dam_convergence_study.json
dam-convergence:
	-$(MAKE) --no-print-directory study STUDY=$(DAM_CONVERGENCE)
	$(BIN) study extrapolate $(DAM_CONVERGENCE) --out pipelines/dam_reference.json

bench: build
	cargo bench --bench explicit
	cargo bench --bench tagger
	cargo bench --bench contact
	cargo bench --bench dam
	cargo bench --bench motion
	cargo bench --bench foundation
	cargo bench --bench forkjoin

# The fuzz properties of tests/all/fuzz.rs with many more cases than `make test` runs
# (FUZZ_CASES per property, default 20000; fixed seed, so a failure reproduces).
FUZZ_CASES ?= 20000
fuzz:
	JQ_FUZZ_CASES=$(FUZZ_CASES) cargo test --release --test all fuzz

fixtures: venv
	GMSH=$(GMSH) scripts/fixtures.sh

clean:
	rm -rf target out build
