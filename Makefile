# fmu-beam: build the engine and the packager, package every scene, test, demo, bench.
# `make demo` and `make test` are the two commands of the README; `make check` is what CI runs.

SHELL := bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := test

PYTHON3 ?= python3
VENV    := .venv
PY      := $(VENV)/bin/python
STAMP   := $(VENV)/.requirements.stamp

HARNESS := target/release/fmu-harness
ENGINE  := target/release/libfmu_beam.so
SCENES  := $(wildcard scenes/*.toml)

.PHONY: .venv tools browser release fmus docs demo test check bench bench-peer example-split example-hinge example-arm example-sweep clean distclean

# The Python environment: created once, refreshed when requirements.txt changes.
.venv: $(STAMP)
$(STAMP): requirements.txt
	$(PYTHON3) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet -r requirements.txt
	touch $@

# System tools the tests use: valgrind (the leak test) and gcc (its C master), from Debian.
tools:
	@command -v gcc >/dev/null && command -v valgrind >/dev/null || { \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind gcc libc6-dev; }

# The browser the animation tests open the HTML player in: Debian's chromium (Playwright, from
# requirements.txt, drives it; it downloads no browser of its own).
browser:
	@command -v chromium >/dev/null || command -v chromium-browser >/dev/null || { \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }

release:
	cargo build --release --workspace

# Every scene as build/fmus/<stem>.fmu. All scenes are tried; a scene that fails leaves no
# (stale) FMU behind and fails the target. FMUs of scenes that no longer exist are removed.
fmus: release
	mkdir -p build/fmus
	for f in build/fmus/*.fmu; do \
	  [[ -e "$$f" ]] || continue; \
	  [[ -e "scenes/$$(basename "$$f" .fmu).toml" ]] || rm -f "$$f"; \
	done
	failed=(); \
	for s in $(SCENES); do \
	  out="build/fmus/$$(basename "$$s" .toml).fmu"; \
	  $(HARNESS) package "$$s" -o "$$out" --binary $(ENGINE) || { rm -f "$$out"; failed+=("$$s"); }; \
	done; \
	if (( $${#failed[@]} )); then echo "fmus: could not package: $${failed[*]}" >&2; exit 1; fi

# The documents generated from the code (issue 16): the scene schema that editors read and the
# scene reference; fmu-harness/tests/generated_docs.rs fails when the committed ones differ.
docs: release
	$(HARNESS) schema -o scenes/scene.schema.json
	$(HARNESS) reference -o docs/scene-reference.md

# C1's plot, then the C3 and C4 (Ω = 10) animations (HTML player, GIF, a still frame).
demo: .venv fmus
	$(PY) tests/demo.py
	$(PY) tests/demo_animations.py

test: .venv tools browser fmus
	cargo test --workspace --release --no-fail-fast
	$(PY) -m pytest tests -q

check:
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	$(MAKE) test

# Work-precision study (fmu-harness work-precision): every case C1-C4 over formulations, integrator
# settings and effects, then the 3D section (C5, C6, the fast variants; `--cases 3D` runs it alone);
# build/bench/REPORT.md, points.csv, <case>.png, and the README's chart. Then dense against sparse
# LU of the iteration matrix by number of substructures (fmu-harness linear-solvers):
# build/bench/LINEAR.md and linear_solvers.csv (the table of docs/linear_algebra.md).
# (tests/bench_c1.py, C1 timed through fmpy, runs by hand: $(PY) tests/bench_c1.py)
bench: .venv release
	$(HARNESS) work-precision --scenes scenes --output build/bench
	$(HARNESS) linear-solvers --scenes scenes --output build/bench
	$(PY) tests/plot_work_precision.py build/bench/points.csv --readme C3 docs/work_precision.png

# Against the peer (issue 12): Exudyn (PyPI, its own venv .venv-bench) runs C2-C4 over elements
# and steps (bench/peer/sweep.py, about 12 min), then this engine over substructures/elements and
# steps or tolerances (fmu-harness peer, about 6 min), both scored against the exact references
# of bench/reference; build/bench/PEER.md has the CPU time ratios at equal accuracy.
VENV_BENCH  := .venv-bench
BENCH_STAMP := $(VENV_BENCH)/.requirements.stamp
$(BENCH_STAMP): requirements-bench.txt
	$(PYTHON3) -m venv $(VENV_BENCH)
	$(VENV_BENCH)/bin/pip install --quiet -r requirements-bench.txt
	touch $@

bench-peer: $(BENCH_STAMP) release
	mkdir -p build/bench
	$(VENV_BENCH)/bin/python bench/peer/sweep.py
	$(HARNESS) peer --scenes scenes --references bench/reference --peer-points build/bench/peer_points.csv --output build/bench

# The split slider-crank (examples/split_slider_crank): the explicit couplings (cosim, the fmpy
# script, the step study), then the joint at the pin (cosim, the fmpy script, the joint study).
example-split: .venv fmus
	mkdir -p build/split
	$(HARNESS) cosim examples/split_slider_crank/system.toml -o build/split/cosim.csv
	$(PY) examples/split_slider_crank/cosim_fmpy.py -o build/split/fmpy.csv
	$(PY) examples/split_slider_crank/study.py
	$(HARNESS) cosim examples/split_slider_crank/joint.toml -o build/split/joint.csv
	$(PY) examples/split_slider_crank/joint_fmpy.py -o build/split/joint_fmpy.csv
	$(PY) examples/split_slider_crank/joint_study.py

# The lag-hinge rotor split at the hinge (examples/hinged_blade): the joint, the hub inertia swept.
example-hinge: .venv fmus
	mkdir -p build/hinged_blade
	$(HARNESS) cosim examples/hinged_blade/system.toml -o build/hinged_blade/cosim.csv
	$(PY) examples/hinged_blade/hub_sweep.py

# The examples (examples/README.md): the flexible arm under PID control (fmpy script) and the
# C4 parameter sweep on Dask (a local cluster of 2 workers; see examples/sweep.py --help).
example-arm: .venv fmus
	$(PY) examples/flexible_arm_pid/arm_pid.py

example-sweep: .venv fmus
	$(PY) examples/sweep.py

clean:
	rm -rf build .pytest_cache tests/__pycache__

distclean: clean
	rm -rf $(VENV)
	cargo clean
