# fmu-beam: build the engine and the packager, package every scene, test, demo, bench.
# `make demo` and `make test` are the two commands of the README; `make check` is what CI runs.
# Every FMU carries binaries/linux64/<id>.so and, where the Windows toolchain is installed
# (`make win64-tools`), binaries/win64/<id>.dll. WIN64=auto (default) builds the Windows engine
# when the toolchain is there and says so when it is not; WIN64=0 never builds it (a quicker
# edit-test loop); WIN64=1 requires it (fails without the toolchain).

SHELL := bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := test

PYTHON3 ?= python3
VENV    := .venv
PY      := $(VENV)/bin/python
STAMP   := $(VENV)/.requirements.stamp
# The linker script (see below, where it is made).
LINKER  := $(VENV)/bin/cc-glibc-2.28

HARNESS := target/release/fmu-harness
BENCH   := target/release/fmu-bench
ENGINE  := target/release/libfmu_beam.so
SCENES  := $(wildcard scenes/*.toml)

# The Windows engine: Debian's second Rust (rustc-web, cargo-web: 1.96, in /usr/bin beside
# rustup's, which stays first on PATH, so called by full path) builds the standard library from
# its source (rust-web-src; -Zbuild-std, allowed by RUSTC_BOOTSTRAP) for the win7 variant of the
# x86_64 windows-gnu target, linked by mingw-w64. win7: its std draws random numbers from
# RtlGenRandom (advapi32) instead of ProcessPrng (bcryptprimitives.dll, Windows 10 on, absent
# from Wine 8), so the DLL is built for Windows 7 and later and runs under Wine: the binary the
# Wine test runs is the one we ship. Its own target dir, so it can build while the Linux one does;
# its build scripts link with the system's cc (not the Linux build's zig, below).
WIN64          ?= auto
WIN64_TARGET   := x86_64-win7-windows-gnu
WIN64_DIR      := target/win64
WIN64_ENGINE   := $(WIN64_DIR)/$(WIN64_TARGET)/release/fmu_beam.dll
WIN64_PACKAGES := rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64
WIN64_TEST_PACKAGES := wine64
# The environment of every Windows build (the engine here, the wheel and the command in wheel-win64).
# It keeps rustc's 16 codegen units a crate (Cargo.toml's release profile has one): with one,
# the Windows engine from clean took the same CPU (488 against 496 s, 2026-12-08) but 5:36
# against 4:52 min, its last crates (faer, fmu-beam) compiling one at a time.
WIN64_ENV      := env -u CARGO_TARGET_X86_64_UNKNOWN_LINUX_GNU_LINKER RUSTC=/usr/bin/rustc \
  RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR=$(WIN64_DIR) CARGO_TARGET_X86_64_WIN7_WINDOWS_GNU_LINKER=x86_64-w64-mingw32-gcc \
  CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16
WIN64_BUILD    := $(WIN64_ENV) nice /usr/bin/cargo build --release -p fmu-beam --target $(WIN64_TARGET) \
  -Zbuild-std=std,panic_unwind
# Exit status 0 when every package of the Windows build is installed (Debian's dpkg).
WIN64_READY    := [[ "$$(dpkg-query -W -f='$${Status}\n' $(WIN64_PACKAGES) 2>/dev/null | grep -c 'install ok installed')" == $(words $(WIN64_PACKAGES)) ]]
WIN64_MISSING  := echo "win64: the Windows toolchain is not installed (Debian packages $(WIN64_PACKAGES);\
 \`make win64-tools\` installs them, as root): the FMUs carry binaries/linux64 only" >&2

.PHONY: .venv tools browser win64-tools test-tools win64 release fmus wheel wheel-win64 docs demo test check fuzz fuzz-python bench bench-peer bench-interleaved bench-accuracy bench-choice bench-studies bench-exhaustive bench-scaling example-split example-hinge example-arm example-sweep example-droop clean distclean

# The Python environment: created with the linker's two packages (below), then completed, and
# refreshed when requirements.txt changes (after the linker, so that two pips never install into
# it at once under make -j; never created again where it is there: a build may be linking
# through its zig meanwhile).
.venv: $(STAMP)
$(STAMP): requirements.txt | $(LINKER)
	$(VENV)/bin/pip install --quiet -r requirements.txt
	touch $@

# The linker of every Linux binary the Makefile builds (the engine, the packager, the tests, the
# wheel's extension module): zig (ziglang, from PyPI), through maturin's wrapper of it (`maturin
# zig cc`, which turns rustc's linker arguments into zig's), against glibc 2.28's symbols. A plain
# link on this Debian (glibc 2.36) binds hypot, pow, exp, log and the pthread keys to glibc
# 2.29-2.35 symbol versions, so an FMU's linux64 engine would not load on an older Linux (RHEL 8,
# Ubuntu 20.04); linked so it needs glibc 2.28 (tests/test_fmus_portable.py checks every FMU), and
# the wheel (manylinux_2_28, below) can carry the same engine and share every compiled unit with
# the Linux build: cargo keeps units apart by linker, and the wheel must be linked so. Cargo reads
# the linker from the environment; the script lives in the venv, whose maturin and ziglang (their
# versions from requirements.txt, installed first, in seconds) it calls. A plain `cargo build`
# outside make links with the system's cc, as cargo does by default (and builds its units apart).
export CARGO_TARGET_X86_64_UNKNOWN_LINUX_GNU_LINKER := $(abspath $(LINKER))
$(LINKER): requirements.txt
	[[ -x $(PY) ]] || $(PYTHON3) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet $$(grep -E '^(maturin|ziglang)==' requirements.txt)
	printf '%s\n' '#!/bin/sh' \
	  'export CARGO_ZIGBUILD_ZIG_COMMAND="$(abspath $(PY))" CARGO_ZIGBUILD_ZIG_COMMAND_ARGS="-m ziglang"' \
	  'exec "$(abspath $(VENV))/bin/maturin" zig cc -- -g -fno-sanitize=all -target x86_64-linux-gnu.2.28 "$$@"' >$@.tmp
	chmod +x $@.tmp && mv $@.tmp $@

# Exit status 0 when each test tool is there: valgrind (the leak test) and gcc (its C master);
# the browser; the Windows build's tools and Wine (its test).
TOOLS_THERE      := { command -v gcc && command -v valgrind; } >/dev/null
BROWSER_THERE    := { command -v chromium || command -v chromium-browser; } >/dev/null
WIN64_TOOLS_THERE := $(WIN64_READY) && command -v wine >/dev/null

# System tools the tests use: valgrind (the leak test) and gcc (its C master), from Debian.
tools:
	@$(TOOLS_THERE) || { \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind gcc libc6-dev; }

# The browser the animation tests open the HTML player in: Debian's chromium (Playwright, from
# requirements.txt, drives it; it downloads no browser of its own).
browser:
	@$(BROWSER_THERE) || { \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }

# The Windows build's tools (and Wine, for its test), from Debian, when missing. A machine where
# they cannot be installed (not Debian, not root, no registry) goes on without them.
win64-tools:
	@[[ "$(WIN64)" == 0 ]] && exit 0; \
	if ! { $(WIN64_TOOLS_THERE); }; then \
	  echo "win64-tools: installing $(WIN64_PACKAGES) $(WIN64_TEST_PACKAGES) from Debian"; \
	  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	      $(WIN64_PACKAGES) $(WIN64_TEST_PACKAGES) >/dev/null; } \
	  || echo "win64-tools: could not install them" >&2; \
	fi

# What `make test` needs from Debian (tools, browser and win64-tools above) in one apt-get run:
# an update and an install, not three of each. Where the whole list cannot be installed, the
# required part (valgrind, gcc, chromium) is tried alone and the Windows toolchain goes, as
# win64-tools allows.
test-tools:
	@pkgs=(); \
	$(TOOLS_THERE) || pkgs+=(valgrind gcc libc6-dev); \
	$(BROWSER_THERE) || pkgs+=(chromium); \
	required=$${#pkgs[@]}; \
	if [[ "$(WIN64)" != 0 ]] && ! { $(WIN64_TOOLS_THERE); }; then \
	  pkgs+=($(WIN64_PACKAGES) $(WIN64_TEST_PACKAGES)); fi; \
	(( $${#pkgs[@]} )) || exit 0; \
	echo "test-tools: installing $${pkgs[*]} from Debian"; \
	apt-get update -qq; \
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$${pkgs[@]}" >/dev/null && exit 0; \
	(( required )) || { echo "test-tools: could not install the Windows toolchain" >&2; exit 0; }; \
	echo "test-tools: installing $${pkgs[*]:0:required} alone" >&2; \
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$${pkgs[@]:0:required}" >/dev/null

# The Rust tests of `make test`: cargo-nextest where installed (the test binaries side by side),
# else cargo test (`=`: asked only where `make test` uses it).
# The Linux build's crates: the workspace but the Python extension, which `wheel` builds
# (maturin, for an explicit target).
LINUX_CRATES := --workspace --exclude fmu-beam-py --release
CARGO_TEST = $(if $(shell cargo nextest --version 2>/dev/null),cargo nextest run --no-fail-fast \
  --cargo-quiet,cargo test --no-fail-fast) $(LINUX_CRATES)
# What it compiles, asked for alone (the same units: `make test` starts it early, in the background).
CARGO_TEST_BUILD := cargo test --no-run $(LINUX_CRATES)

release: $(LINKER)
	cargo build $(LINUX_CRATES)

# The Windows engine ($(WIN64_ENGINE)), when the toolchain is there; about 5 minutes from clean
# on 2 cores (the standard library is built too), seconds when up to date. Waits for a build
# already running in $(WIN64_DIR) (cargo's lock), e.g. the one `make test` starts.
win64:
	@if [[ "$(WIN64)" == 0 ]]; then exit 0; fi; \
	if $(WIN64_READY); then \
	  $(WIN64_BUILD); \
	elif [[ "$(WIN64)" == 1 ]]; then \
	  $(WIN64_MISSING); echo "win64: WIN64=1 requires it" >&2; exit 1; \
	else \
	  $(WIN64_MISSING); \
	fi

# Every scene as build/fmus/<stem>.fmu, with the Linux engine and (see win64) the Windows one.
# All scenes are tried; a scene that fails leaves no (stale) FMU behind and fails the target.
# FMUs of scenes that no longer exist are removed.
fmus: release win64
	mkdir -p build/fmus
	for f in build/fmus/*.fmu; do \
	  [[ -e "$$f" ]] || continue; \
	  [[ -e "scenes/$$(basename "$$f" .fmu).toml" ]] || rm -f "$$f"; \
	done
	binaries=(--binary linux64=$(ENGINE)); \
	if [[ "$(WIN64)" != 0 ]] && $(WIN64_READY); then binaries+=(--binary win64=$(WIN64_ENGINE)); fi; \
	failed=(); \
	for s in $(SCENES); do \
	  out="build/fmus/$$(basename "$$s" .toml).fmu"; \
	  $(HARNESS) package "$$s" -o "$$out" "$${binaries[@]}" || { rm -f "$$out"; failed+=("$$s"); }; \
	done; \
	if (( $${#failed[@]} )); then echo "fmus: could not package: $${failed[*]}" >&2; exit 1; fi

# The Python package (issue 30; pyproject.toml, python/): dist/fmu_beam-<version>-cp39-abi3-
# manylinux_2_28_x86_64.whl, one wheel for every CPython >= 3.9 on x86-64 Linux with glibc >= 2.28,
# with the packager (the extension module fmu_beam._native, PyO3) and both engines as package data
# (python/fmu_beam/engines/, which git ignores), so that its FMUs carry linux64 and win64.
# maturin builds the extension module in target/ through the Linux build's linker (LINKER above:
# glibc 2.28, which maturin's manylinux_2_28 audit checks), so it finds every unit but its own
# crate and PyO3 built, and the linux64 engine it carries is the FMUs' ($(ENGINE)). Two things
# keep the units shared: no --zig or --target (maturin would pass an explicit target and its own
# linker), and the same features: cargo resolves features per build, and PyO3 asks more of syn
# and once_cell than the rest of the workspace does, so fmu-bench (bench/Cargo.toml) asks for them
# too; where they differ, maturin compiles every dependency again (a minute or two; `maturin
# build -v` says "Dirty ... info of dependency ... changed"). The win64 engine is `make win64`'s.
# The wheel is then installed into .venv (its dependencies are requirements.txt's), where the
# tests of the Python API import it. A pass with no engines in place (`make test` runs one into
# build/wheel/early in the background, to compile) packs a wheel without them.
WHEEL_ENGINES := python/fmu_beam/engines
# Every maturin pass holds build/wheel/maturin.lock: maturin stages the library at one fixed path
# of target/, and two passes at once (the background pass still running when `wheel` starts)
# race on it ("failed to stage ...").
MATURIN       := PATH="$(abspath $(VENV))/bin:$$PATH" flock build/wheel/maturin.lock \
  nice $(VENV)/bin/maturin build --release --compatibility manylinux_2_28
wheel: .venv release
	rm -rf $(WHEEL_ENGINES) build/wheel/early dist/fmu_beam-*.whl
	$(MAKE) --no-print-directory win64
	mkdir -p build/wheel $(WHEEL_ENGINES)/linux64
	cp $(ENGINE) $(WHEEL_ENGINES)/linux64/
	if [[ "$(WIN64)" != 0 ]] && $(WIN64_READY); then \
	  mkdir -p $(WHEEL_ENGINES)/win64 && cp $(WIN64_ENGINE) $(WHEEL_ENGINES)/win64/; fi
	$(MATURIN) --out dist
	$(PY) -m pip install --quiet --no-deps --force-reinstall dist/fmu_beam-*manylinux*.whl

# The win64 wheel (issue 30), not part of `make test` (about 5 more minutes of build): the same
# package cross-built with the Windows engine's toolchain (Debian's rustc-web, -Zbuild-std,
# mingw-w64; PyO3 links python3.dll by raw-dylib, so no Python import library is needed) into
# dist/fmu_beam-<version>-cp39-abi3-win_amd64.whl, with the engines `make wheel` put in; and the
# packager's command built the same way (target/win64/.../fmu-harness.exe), which
# tests/test_wheel.py runs under Wine when it finds both.
WIN64_HARNESS := $(WIN64_DIR)/$(WIN64_TARGET)/release/fmu-harness.exe
wheel-win64: wheel
	@$(WIN64_READY) || { $(WIN64_MISSING); exit 1; }
	$(WIN64_ENV) PATH="/usr/bin:/bin:$(abspath $(VENV))/bin" nice $(VENV)/bin/maturin build --release \
	  --target $(WIN64_TARGET) -Z build-std=std,panic_unwind --out dist
	$(WIN64_ENV) nice /usr/bin/cargo build --release -p fmu-harness --bin fmu-harness --target $(WIN64_TARGET) -Zbuild-std=std,panic_unwind

# The documents generated from the code (issue 16): the scene schema that editors read and the
# scene reference; fmu-harness/tests/generated_docs.rs fails when the committed ones differ.
docs: release
	$(HARNESS) schema -o scenes/scene.schema.json
	$(HARNESS) reference -o docs/scene-reference.md

# The fuzz stage (issue 45): seeded and bounded in time, it fails on a crash, a hang or a
# non-finite output with fmi2OK. Each half is one line: FMI 2.0 call sequences and scene
# mutations through the engine's exported fmi2* functions (tests/fuzz/fmi_calls.py, about
# FUZZ_SECONDS plus the packaging of the units). FUZZ_SEED picks the sequences.
FUZZ_SEED    ?= 45
FUZZ_SECONDS ?= 120
fuzz: .venv release
	nice $(PY) tests/fuzz/fmi_calls.py --engine $(ENGINE) --harness $(HARNESS) --seed $(FUZZ_SEED) --seconds $(FUZZ_SECONDS)

# The fuzz stage's Python half (issue 45, item 9): hostile Python objects (self-reference, deep
# nesting, hostile tolist/items/__str__/__float__/__index__, subclasses with lying methods, huge
# ints, NaN, bytes, sets, generators) thrown at Scene.from_dict, from_toml, load, package, modes,
# simulate and the command, seeded and bounded in time (tests/fuzz/python_objects.py, about
# FUZZ_PYTHON_SECONDS, some 20 cases a second and worker); a crash, a hang or an internal error
# fails it. FUZZ_PYTHON_JOBS workers (default: every core) take batches of cases in turn (a
# case's number and seed reproduce it alone, whatever the number of workers).
# It uses the fmu_beam installed in .venv (`make wheel`).
FUZZ_PYTHON_SEED    ?= 45
FUZZ_PYTHON_SECONDS ?= 60
FUZZ_PYTHON_JOBS    ?= $(shell nproc)
fuzz-python: .venv
	nice $(PY) tests/fuzz/python_objects.py --seed $(FUZZ_PYTHON_SEED) --seconds $(FUZZ_PYTHON_SECONDS) \
	  --jobs $(FUZZ_PYTHON_JOBS)

# C1's plot, then the C3 and C4 (Ω = 10) animations (HTML player, GIF, a still frame).
demo: .venv fmus
	$(PY) tests/demo.py
	$(PY) tests/demo_animations.py

# What runs side by side, so that a fresh clone's `make test` keeps both cores busy (issue 46
# item 6; every stage is CPU-bound, so what counts is that no core idles: `vmstat 10` beside a
# fresh clone's run read 0 % idle but where one job was left alone):
# - the Rust tests' compile, which builds the engine, the packager and its command on the way,
#   starts at once in the background (once the linker is there, seconds), then the rest of the
#   Linux build (the bench command), then the wheel's extension module (a maturin pass that
#   finds the rest built: see wheel; log: build/release.log): in one cargo run the engine's tests
#   compile beside the packager, where two runs in turn wait on each crate of the chain faer,
#   fmu-beam, fmu-harness (44, 43, 18 s here, `cargo build --timings`). Meanwhile Python's venv
#   and Debian's packages install side by side (about two minutes of download and unpacking on
#   a fresh machine, little CPU).
# - Then the Windows engine (log: build/win64/build.log), niced, in the background, while
#   `release` and the Rust tests run in front (each waits for cargo's lock and finds its units
#   built). Run at normal priority, it slowed the Rust tests as much as it saved at the end (980 s
#   against 981); started at once beside the Linux build (toolchain already installed), the run
#   took 829 s against 797 (1538 against 1464 CPU s).
# - tests/test_no_leaks.py (1e4 cycles under valgrind, 2-3 min on one core; its own --basetemp,
#   its output after the rest's), niced in the background as soon as the Linux engine is built,
#   on a unit of its own that carries that engine only.
# - The Rust tests under cargo-nextest where it is installed (every test binary side by side;
#   `cargo test` runs a binary's tests in threads).
# - The fuzz stage's FMI half (tests/fuzz/fmi_calls.py; issue 45 item 9, shorter than `make
#   fuzz` alone, bounded in time, output in build/fuzz.log) once no maturin pass runs
#   (maturin.lock), at normal priority, beside the end of the Windows engine's build (its last
#   crates, faer and fmu-beam, compile one at a time: a core idled there for a minute) and the
#   units' packaging; `wheel` then finds its extension module built.
# - pytest in two workers (pytest-xdist, a file's tests in one worker: its module fixtures are
#   built once), then the fuzz stage's Python half (it needs the wheel; build/fuzz-python.log)
#   on both cores for 15 s (one worker for 30 s before: the same CPU time, one core idle).
TEST_FUZZ_SECONDS        ?= 60
TEST_FUZZ_PYTHON_SECONDS ?= 15
# The exit status a background job of `test` left in the file $(1) (waits up to 30 min for it;
# 1 when it never came).
rc_of = for ((i = 0; i < 1800; i++)); do [[ -e $(1) ]] && break; sleep 1; done; cat $(1) 2>/dev/null || echo 1
test: $(LINKER)
	@mkdir -p build/wheel; echo "release: the Rust tests' compile, the Linux build and the wheel's extension module in the background (build/release.log)"; \
	{ $(CARGO_TEST_BUILD) && cargo build $(LINUX_CRATES) && $(MATURIN) --out build/wheel/early; } </dev/null >build/release.log 2>&1 &
	$(MAKE) --no-print-directory -j2 -Otarget .venv test-tools
	@mkdir -p build/win64; \
	if [[ "$(WIN64)" != 0 ]] && $(WIN64_READY); then \
	  echo "win64: building the Windows engine in the background (build/win64/build.log)"; \
	  $(WIN64_BUILD) </dev/null >build/win64/build.log 2>&1 & \
	fi
	$(MAKE) --no-print-directory release
	@mkdir -p build/leaks; rm -f build/pytest-leaks.rc build/fuzz.rc; \
	$(HARNESS) package scenes/cantilever_free_vibration.toml -o build/leaks/cantilever_free_vibration.fmu \
	  --binary linux64=$(ENGINE) >/dev/null; \
	echo "pytest: tests/test_no_leaks.py in the background, niced (build/pytest-leaks.log)"; \
	{ FMU_BEAM_LEAK_FMU=build/leaks/cantilever_free_vibration.fmu nice $(PY) -m pytest tests/test_no_leaks.py \
	    -q -p no:cacheprovider --basetemp=build/pytest-leaks >build/pytest-leaks.log 2>&1; \
	  echo $$? >build/pytest-leaks.rc; } </dev/null &
	$(CARGO_TEST)
	@flock build/wheel/maturin.lock true; echo "make fuzz: in the background (build/fuzz.log)"; \
	{ $(PY) tests/fuzz/fmi_calls.py --engine $(ENGINE) --harness $(HARNESS) --seed $(FUZZ_SEED) \
	    --seconds $(TEST_FUZZ_SECONDS) >build/fuzz.log 2>&1; echo $$? >build/fuzz.rc; } </dev/null &
	$(MAKE) --no-print-directory fmus
	$(MAKE) --no-print-directory wheel
	@rest=0; WIN64=$(WIN64) $(PY) -m pytest tests -q -n 2 --dist loadfile --ignore=tests/test_no_leaks.py || rest=$$?; \
	pyfuzzed=0; $(MAKE) --no-print-directory fuzz-python FUZZ_PYTHON_SECONDS=$(TEST_FUZZ_PYTHON_SECONDS) \
	  >build/fuzz-python.log 2>&1 || pyfuzzed=$$?; \
	leaked=$$($(call rc_of,build/pytest-leaks.rc)); fuzzed=$$($(call rc_of,build/fuzz.rc)); \
	echo "pytest tests/test_no_leaks.py:"; cat build/pytest-leaks.log; \
	echo "make fuzz:"; cat build/fuzz.log; echo "make fuzz-python:"; cat build/fuzz-python.log; \
	exit $$(( rest || leaked || fuzzed || pyfuzzed ))

check: $(LINKER)
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	$(MAKE) test

# Work-precision study (fmu-bench work-precision, bench/): every case C1-C4 over formulations, integrator
# settings and effects, then the 3D section (C5, C6, the fast variants; `--cases 3D` runs it alone);
# build/bench/REPORT.md, points.csv, <case>.png, and the README's chart. Then dense against sparse
# LU of the iteration matrix by number of substructures (fmu-bench linear-solvers):
# build/bench/LINEAR.md and linear_solvers.csv (the table of docs/linear_algebra.md).
# (tests/bench_c1.py, C1 timed through fmpy, runs by hand: $(PY) tests/bench_c1.py)
bench: .venv release
	$(BENCH) work-precision --scenes scenes --output build/bench
	$(BENCH) linear-solvers --scenes scenes --output build/bench
	$(PY) tests/plot_work_precision.py build/bench/points.csv --readme C3 docs/work_precision.png

# Against the peer (issue 12): Exudyn (PyPI, its own venv .venv-bench) runs C2-C4 over elements
# and steps (bench/peer/sweep.py; C2 and C3 4 min each with the meshes between the doublings,
# 2026-12-07), then this engine over substructures/elements and steps or tolerances
# (fmu-bench peer; C2 5 min, C3 with C4 Ω = 4 another 5; C2 may take 20 s a run), both scored
# against the exact references of bench/reference; build/bench/PEER.md has the CPU time ratios
# at equal accuracy. Then the shipped C2-C4 scenes as a user runs them (issue 34 item 3: their
# FMUs in fmpy with their own settings, interleaved with Exudyn's cheapest run as accurate;
# bench/peer/as_shipped.py, about 2 min): build/bench/AS_SHIPPED.md.
VENV_BENCH  := .venv-bench
BENCH_STAMP := $(VENV_BENCH)/.requirements.stamp
$(BENCH_STAMP): requirements-bench.txt
	$(PYTHON3) -m venv $(VENV_BENCH)
	$(VENV_BENCH)/bin/pip install --quiet -r requirements-bench.txt
	touch $@

bench-peer: $(BENCH_STAMP) release fmus
	mkdir -p build/bench
	$(VENV_BENCH)/bin/python bench/peer/sweep.py
	$(BENCH) peer --scenes scenes --references bench/reference --peer-points build/bench/peer_points.csv --output build/bench
	$(VENV_BENCH)/bin/python bench/peer/as_shipped.py

# The peer table timed again interleaved (issue 34 item 4): the runs behind each ratio of the
# last `make bench-peer` (its build/bench/ours_points.csv and peer_points.csv; not rerun here)
# and, on each side, those within 1.25 x of them (issue 46), ours (`fmu-bench peer-run`) and
# Exudyn's in turns, 5 rounds (3 for the longest); build/bench/INTERLEAVED.md and
# interleaved.csv; about 3-10 min.
bench-interleaved: $(BENCH_STAMP) release
	$(VENV_BENCH)/bin/python bench/peer/interleaved.py

# The accuracy study checked against the truth (issue 34 item 2): `fmu-harness accuracy` on the
# shipped C2-C4 scenes at targets 1e-2, 1e-3, 1e-4 with --reference bench/reference/<case>.csv,
# each study's report in build/accuracy/<case>-<target>.md (its "Against the reference" line:
# the chosen setting's true error and estimate / true); the default counted budget (600, both
# studies) and --jobs (every core). Each case
# names the reference's grid (--comm) and the ladders' start (--step, and Newton's tolerance
# 1e-6): the steps the scenes had before the study tuned them (issue 34), so that the study
# does not start from its own earlier answer.
ACCURACY_CASES = spin_up_omega10:c4_omega10:beam.tip.deflection:tip_deflection:1e-2:5e-2 \
	spin_up_omega4:c4_omega4:beam.tip.deflection:tip_deflection:1e-2:5e-2 \
	slider_crank_rigid_crank:c3_rigid:slider.position:slider_position:1e-3:1e-2 \
	slider_crank:c3_elastic:slider.position:slider_position:1e-3:1e-2 \
	flexible_pendulum_substructured:c2:beam.tip.deflection:tip_deflection:1e-3:1e-2
bench-accuracy: release
	mkdir -p build/accuracy
	for c in $(ACCURACY_CASES); do \
	  IFS=: read scene case output column comm step <<< "$$c"; \
	  for t in 1e-2 1e-3 1e-4; do \
	    $(HARNESS) accuracy scenes/$$scene.toml --output $$output --target $$t \
	      --comm $$comm --step $$step --newton 1e-6 \
	      --reference bench/reference/$$case.csv --column $$column \
	      --dir build/accuracy/$$case-$$t > build/accuracy/$$case-$$t.md || exit 1; \
	    echo "$$case $$t: $$(grep -o 'Against the reference.*\|No setting.*' build/accuracy/$$case-$$t.md)"; \
	  done; \
	done

# The accuracy study's choice against an exhaustive sweep (issue 46 item 1: at most 1.5x the
# cheapest setting meeting the target with the study's own safety factor): after `make
# bench-accuracy`, `fmu-bench exhaustive` runs each case of ACCURACY_CASES at every mesh the
# study reaches and every quarter octave of its steps (Newton 1e-6) against the exact
# references, then times each study's chosen.toml against the sweep's cheapest (5 rounds, the
# order alternating), and fits the counted cost to CPU time; build/bench/EXHAUSTIVE.md and
# exhaustive.csv. About 70 min on this 2-core machine (C2 most of it); EXHAUSTIVE_POINTS=<csv>
# reuses an earlier sweep's points.
EXHAUSTIVE_POINTS ?=
bench-exhaustive: release
	mkdir -p build/bench
	nice $(BENCH) exhaustive --scenes scenes --references bench/reference --output build/bench \
	  --studies build/accuracy $(if $(EXHAUSTIVE_POINTS),--points $(EXHAUSTIVE_POINTS))

# How the engine's cost grows with the model (issue 46 item 3): C2's pendulum as n substructures
# of one element and as one frame of n elements, n = 4 ... 128; set-up (Engine::new to
# exit_initialization) and CPU time per step at a fixed step 1e-3 s, with Newton iterations and
# iteration matrices, medians of 5 rounds and the exponents fitted on log-log
# (fmu-bench scaling); build/bench/SCALING.md, the table of docs/accuracy.md. About 2 min.
bench-scaling: release
	mkdir -p build/bench
	nice $(BENCH) scaling --scenes scenes --output build/bench

# The accuracy study's choice against the peer bench's cheapest setting (issue 34 item 2: at
# most 1.5x): after `make bench-accuracy` and `make bench-peer` (build/bench/ours_points.csv),
# each study's chosen.toml and the cheapest of our peer points meeting the same target on the
# same output, timed in one process (`fmu-bench choice`, 5 rounds, the order alternating);
# writes build/accuracy/CHOICE.md. CHOICE_SCENES: the scenes the peer sweep ran, where they are not
# these (the peer's settings are rebuilt from them).
CHOICE_SCENES ?= scenes
bench-choice: release
	mkdir -p build/accuracy
	h=--header; : > build/accuracy/CHOICE.md; \
	for c in $(ACCURACY_CASES); do \
	  IFS=: read scene case output column comm step <<< "$$c"; \
	  for t in 1e-2 1e-3 1e-4; do \
	    f=build/accuracy/$$case-$$t/chosen.toml; \
	    if [ -f $$f ]; then \
	      nice $(BENCH) choice --scenes $(CHOICE_SCENES) --case $$case --output $$column --target $$t --chosen $$f $$h \
	        >> build/accuracy/CHOICE.md 2> build/accuracy/choice.err && h= \
	      || echo "| $$case $$column | $$t | $$(tail -1 build/accuracy/choice.err) | | |" >> build/accuracy/CHOICE.md; \
	    else echo "| $$case $$column | $$t | no choice (target not met) | | |" >> build/accuracy/CHOICE.md; fi; \
	    tail -1 build/accuracy/CHOICE.md; \
	  done; \
	done

# What the Python studies cost (issue 44): Scene.simulate against fmpy, a 32-variant sweep on 1
# and 2 local processes and Dask workers, what a task ships (bench/studies.py, about 8 min);
# build/bench/STUDIES.md.
bench-studies: wheel fmus
	$(PY) bench/studies.py

# The split slider-crank (examples/split_slider_crank): the explicit couplings (cosim, the fmpy
# script, the step study), then the joint at the pin (cosim, the fmpy script, the joint study).
example-split: .venv fmus
	mkdir -p build/split
	$(HARNESS) cosim examples/split_slider_crank/system.toml -o build/split/cosim.csv
	$(PY) examples/split_slider_crank/cosim_fmpy.py -o build/split/fmpy.csv
	$(PY) examples/split_slider_crank/study.py
	$(HARNESS) cosim examples/split_slider_crank/joint.toml -o build/split/joint.csv
	$(PY) examples/split_slider_crank/joint_fmpy.py -o build/split/joint_fmpy.csv
	$(PY) examples/split_slider_crank/joint_study.py --readme

# The lag-hinge rotor split at the hinge (examples/hinged_blade): the joint, the hub inertia swept.
example-hinge: .venv fmus
	mkdir -p build/hinged_blade
	$(HARNESS) cosim examples/hinged_blade/system.toml -o build/hinged_blade/cosim.csv
	$(PY) examples/hinged_blade/hub_sweep.py --readme

# The examples (examples/README.md): the flexible arm under PID control (fmpy script) and the
# C4 parameter sweep on Dask (a local cluster of 2 workers; see examples/sweep.py --help).
example-arm: .venv fmus
	$(PY) examples/flexible_arm_pid/arm_pid.py
	$(PY) examples/flexible_arm_pid/arm_pid.py --table

example-sweep: .venv fmus
	$(PY) examples/sweep.py

# The worked study of docs/python.md: the blade's droop over speed and modulus (fmu_beam.sweep on
# every core; the wheel installed in .venv, as `make wheel` leaves it).
example-droop: wheel
	$(PY) examples/blade_droop/droop_sweep.py

clean:
	rm -rf build dist $(WHEEL_ENGINES) .pytest_cache tests/__pycache__

distclean: clean
	rm -rf $(VENV)
	cargo clean
