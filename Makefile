# The two README commands: `make run` and `make test`. Everything else is a helper.
BUILD ?= build
JOBS ?= $(shell nproc)
OUT ?= out
# CI compiles shadowfilter's own code with -Werror; elsewhere a new compiler's warning does not
# stop `make run`.
WERROR ?= $(if $(CI),ON,OFF)

.PHONY: deps deps-bench deps-dev configure build run test python-env bench bench-smoke performance data meshes mesh-scenes coherent-table clean
.PHONY: fresh-check oclgrind sanitize fuzz tidy format format-check

deps:
	@scripts/install-deps.sh core

deps-bench:
	@scripts/install-deps.sh bench

deps-dev:
	@scripts/install-deps.sh dev

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DSF_WARNINGS_AS_ERRORS=$(WERROR) \
	    -DCMAKE_EXPORT_COMPILE_COMMANDS=ON > $(BUILD).configure.log 2>&1 || (cat $(BUILD).configure.log; exit 1)

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Main job: ESM (its defaults: c = 120 with z-max classification) with a Gaussian prefilter on
# the bundled default scene. Builds the command alone (not the test suite).
run: configure
	@cmake --build $(BUILD) -j $(JOBS) --target shadowfilter_cli
	@mkdir -p $(OUT)
	$(BUILD)/shadowfilter filter --shadow-map data/spheres/shadowmap.exr \
	    --receivers data/spheres/receivers.exr -o $(OUT)/spheres_esm.exr \
	    --method esm --blur-radius 3 --preview shaded
	$(BUILD)/shadowfilter filter --shadow-map data/spheres/shadowmap.exr \
	    --receiver-depth data/spheres/receiver_depth.exr -o $(OUT)/spheres_esm_planar.exr \
	    --method esm --blur-radius 3
	@echo "output images: $(OUT)/spheres_esm.exr (camera view; to look at: $(OUT)/spheres_esm_shaded.png, the scene shaded by the light, and $(OUT)/spheres_esm.png, the visibility), $(OUT)/spheres_esm_planar.exr (planar receiver)"

# The whole suite, C++ and Python (ctest runs pytest as Python.pytest, label python), in one
# pass; one layer of it: cd build && ctest -L core (labels: core, reference, io, cli, tools,
# package, python; docs/development.md, "Tests"). The Python package's module is built in the
# same tree against a virtual environment under the build directory (Debian's Python is
# externally managed).
PYTHON ?= python3
VENV = $(BUILD)/venv
$(VENV)/ready: python/requirements-test.txt
	@$(PYTHON) -m venv $(VENV) || (echo "make test: $(PYTHON) -m venv failed (Debian: apt install python3-venv)"; exit 1)
	@$(VENV)/bin/pip install -q --disable-pip-version-check -r python/requirements-test.txt
	@touch $@

python-env: deps $(VENV)/ready

test: python-env
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DSF_WARNINGS_AS_ERRORS=$(WERROR) \
	    -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DSF_PYTHON=ON -DPython_EXECUTABLE=$(abspath $(VENV))/bin/python \
	    > $(BUILD).configure.log 2>&1 || (cat $(BUILD).configure.log; exit 1)
	@cmake --build $(BUILD) -j $(JOBS)
	@cd $(BUILD) && ctest --output-on-failure -j 2

# The whole suite with AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer included) on
# shadowfilter's own code, in its own build directory (docs/development.md). Every report fails:
# ASan, LSan and UBSan end the process with exit code 86, and since a CLI test may expect a failing
# exit code anyway, ASan and LSan also write their reports to $(SANITIZE_BUILD)/sanitizer-logs,
# which must stay empty (UBSan, a second runtime next to ASan's, ignores log_path and reports on
# stderr). The suppressions (scripts/sanitize/*.supp) name third-party libraries only.
# Every label of the suite but one test: Package.AddSubdirectory configures and builds a copy of
# the core library of its own, without sanitizers, so that it checks nothing here that `make test`
# does not (Package.InstallAndEmbed stays: it builds and runs the embedding example instrumented).
# The tools and reference labels stay too: their code (evaluate, the scene generator, coherent
# rendering, the references) is shadowfilter's own and this is the only pass that checks its
# memory. CTEST_ARGS: more ctest arguments, e.g. CTEST_ARGS='-L io' for a part of the suite.
SANITIZE_BUILD ?= build-sanitize
SANITIZE_LOGS = $(abspath $(SANITIZE_BUILD))/sanitizer-logs
SANITIZE_SUPP = $(CURDIR)/scripts/sanitize
CTEST_ARGS ?=
# intercept_tls_get_addr=0: gcc 12's LeakSanitizer can crash in its tracer at exit ("Tracer caught
# signal 11") on dynamic TLS blocks of dlopen'ed libraries (PoCL's); docs/development.md.
sanitize: export ASAN_OPTIONS = detect_leaks=1:exitcode=86:intercept_tls_get_addr=0:log_path=$(SANITIZE_LOGS)/asan
sanitize: export LSAN_OPTIONS = suppressions=$(SANITIZE_SUPP)/lsan.supp:print_suppressions=0
sanitize: export UBSAN_OPTIONS = print_stacktrace=1:halt_on_error=1:exitcode=86:suppressions=$(SANITIZE_SUPP)/ubsan.supp
# -O1 -g1 (ASan's own advice; line tables are enough for the reports' stacks): the instrumented
# build at -O2 -g was most of this target's time (host/cli/cmd_filter.cpp alone: 114 s, against
# 51 s at -O1 -g1 and 20 s for the Release build).
sanitize: deps
	@cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSF_SANITIZE=ON \
	    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
	    -DSF_WARNINGS_AS_ERRORS=$(WERROR) > $(SANITIZE_BUILD).configure.log 2>&1 || (cat $(SANITIZE_BUILD).configure.log; exit 1)
	@rm -rf $(SANITIZE_LOGS) && mkdir -p $(SANITIZE_LOGS)
	@cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	@rc=0; (cd $(SANITIZE_BUILD) && ctest --output-on-failure -j 2 -E '^Package[.]AddSubdirectory$$' $(CTEST_ARGS)) || rc=$$?; \
	  n=$$(ls $(SANITIZE_LOGS) | wc -l); \
	  for f in $(SANITIZE_LOGS)/*; do [ -f "$$f" ] && { echo "== $$f"; head -n 60 "$$f"; }; done; \
	  echo "sanitize: ctest exit $$rc, $$n sanitizer report(s) in $(SANITIZE_LOGS)"; \
	  [ $$rc = 0 ] && [ $$n = 0 ]

# libFuzzer harnesses of every parser (tests/fuzz; docs/development.md, "Fuzzing"): clang 14 builds
# them with ASan and UBSan in $(FUZZ_BUILD), with only the parsers they reach; each then runs for
# FUZZ_SECONDS from a scratch copy of its committed corpus and regressions, FUZZ_PARALLEL at a
# time (7 harnesses, 2 at a time: 4 rounds of 50 s on 2 cores). It prints each harness's executions per
# second and in all, and fails on any crash, sanitizer report, leak, timeout or out-of-memory,
# the input that did it left in $(FUZZ_BUILD)/fuzz-work/<harness>/.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 50
FUZZ_PARALLEL ?= $(JOBS)
fuzz:
	@scripts/install-deps.sh fuzz
	@cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 -DSF_FUZZ=ON \
	    -DSF_BUILD_TESTS=OFF -DSF_INSTALL=OFF -DSF_WARNINGS_AS_ERRORS=$(WERROR) \
	    > $(FUZZ_BUILD).configure.log 2>&1 || (cat $(FUZZ_BUILD).configure.log; exit 1)
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target sf_fuzzers
	@scripts/fuzz.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_PARALLEL)

# clang-tidy (.clang-tidy) over the core library's sources, with their headers, through the
# compile_commands.json of $(BUILD) (configured, not built). Any finding fails.
CLANG_TIDY ?= clang-tidy
TIDY_SRC = $(sort $(wildcard host/src/*/*.cpp))
tidy: configure deps-dev
	@printf '%s\n' $(TIDY_SRC) | xargs -P $(JOBS) -n 1 $(CLANG_TIDY) -p $(BUILD) --quiet \
	  && echo "tidy: $(words $(TIDY_SRC)) files clean"

# Every benchmark, 3 repetitions of >= 0.05 s (5 of >= 0.2 s when sf_bench runs by hand): the
# full default settings took over 40 minutes on the loaded 2-core machine. The JSON is written to
# a temporary file and checked before it replaces $(OUT)/bench.json.
BENCH_REPETITIONS ?= 3
BENCH_MIN_TIME ?= 0.05
BENCH_ARGS ?=
bench: build deps-bench
	@cmake -S . -B $(BUILD) -DSF_BUILD_BENCH=ON > /dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target sf_bench
	@mkdir -p $(OUT)
	SF_BENCH_REPETITIONS=$(BENCH_REPETITIONS) SF_BENCH_MIN_TIME=$(BENCH_MIN_TIME) \
	    $(BUILD)/sf_bench --benchmark_out=$(OUT)/bench.json.part --benchmark_out_format=json $(BENCH_ARGS)
	@python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); n = len(d["benchmarks"]); \
	    e = [b["name"] for b in d["benchmarks"] if b.get("error_occurred")]; \
	    print(f"bench: {n} results, {len(e)} with errors {e}")' $(OUT)/bench.json.part
	@mv $(OUT)/bench.json.part $(OUT)/bench.json && echo "bench: wrote $(OUT)/bench.json"

# docs/performance.md: the seeds' performance tables (bench/bench_tables.cpp) and the default
# frame's stages against their floor or peer, measured in one sf_bench run (the copy bandwidth
# first, ours beside each baseline under the same load) and written by
# scripts/performance_tables.py; the run's JSON stays in $(BUILD)/performance.json, a one-shot
# process's against the bench's frame (scripts/one_shot.sh) in $(BUILD)/one_shot.json. A GPU run
# of the same filter fills the GPU column (docs/gpu.md, scripts/gpu/).
PERF_FILTER ?= ^copy/|^table|^coherent/query_|^esm_classify/frame/size:2048/|^blur/(ours|opencv_GaussianBlur)/size:2048/|^mips/chain/size:2048/|^esm_vs_opencv/|^esm_reconstruct/points_on_2048/lookup:1/rx:./vec:16/joined:1/|^esm_reconstruct/bound/taps:8/rx:0/|^esm_classify/fresh_frame/size:2048/
performance: build deps-bench
	@cmake -S . -B $(BUILD) -DSF_BUILD_BENCH=ON > /dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target sf_bench
	SF_BENCH_REPETITIONS=$(BENCH_REPETITIONS) $(BUILD)/sf_bench --benchmark_filter='$(PERF_FILTER)' \
	    --benchmark_out=$(BUILD)/performance.json --benchmark_out_format=json
	scripts/one_shot.sh $(BUILD) 5 $(BUILD)/one_shot.json
	python3 scripts/performance_tables.py --cpu $(BUILD)/performance.json $(BUILD)/one_shot.json --out docs/performance.md

# Every benchmark family and variant once, at the least time (1 repetition, one timed run after
# the warm-up) and at a small size (SF_BENCH_SMOKE=1: maps of at most 512, 320x180 receivers;
# bench/bench_common.hpp): what CI runs so that a benchmark that breaks (an error, a failed
# agreement check such as esm_vs_opencv's) fails the build instead of waiting for the next
# `make bench`. Its figures mean nothing; the JSON is kept in $(BUILD)/bench-smoke.json.
bench-smoke: build deps-bench
	@cmake -S . -B $(BUILD) -DSF_BUILD_BENCH=ON > /dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target sf_bench
	@SF_BENCH_SMOKE=1 SF_BENCH_REPETITIONS=1 SF_BENCH_MIN_TIME=0.0001 $(BUILD)/sf_bench \
	    --benchmark_out=$(BUILD)/bench-smoke.json --benchmark_out_format=json > $(BUILD)/bench-smoke.log 2>&1 \
	  || { tail -n 20 $(BUILD)/bench-smoke.log; echo "bench-smoke: sf_bench failed"; exit 1; }
	@python3 -c 'import json, sys; b = json.load(open(sys.argv[1]))["benchmarks"]; \
	    e = [x["name"] + ": " + x.get("error_message", "") for x in b if x.get("error_occurred")]; \
	    print(f"bench-smoke: {len(b)} benchmarks, {len(e)} with errors"); [print("  " + m) for m in e]; \
	    sys.exit(1 if e or not b else 0)' $(BUILD)/bench-smoke.json

# Regenerates the bundled scenes in data/ (deterministic: same files, byte for byte).
DATA_SCENES ?= spheres fence backyard contact thin
data: build
	@for s in $(DATA_SCENES); do \
	  $(BUILD)/shadowfilter scene $$s -o data/$$s --size 512 --receivers 640x480 --samples 64 --seed 1 || exit 1; \
	done

# Scanned meshes from Debian's libcgal-demo (not committed): extracted into $(BUILD)/meshes,
# scenes written to $(OUT)/mesh-scenes/NAME at the issue's full size.
MESHES ?= bunny00 ChineseDragon-10kv armadillo elephant
MESH_ARGS ?= --size 2048 --receivers 1920x1080 --samples 64
CGAL_DATA ?= /usr/share/doc/libcgal-demo/data.tar.gz
meshes: build
	@scripts/install-deps.sh meshes
	@mkdir -p $(BUILD)/meshes
	@tar xzf $(CGAL_DATA) -C $(BUILD)/meshes --strip-components 2 \
	    $(foreach m,$(MESHES),data/meshes/$(m).off)
	@ls -l $(BUILD)/meshes

mesh-scenes: meshes
	@for m in $(MESHES); do \
	  $(BUILD)/shadowfilter scene $(BUILD)/meshes/$$m.off -o $(OUT)/mesh-scenes/$$m $(MESH_ARGS) || exit 1; \
	done

# Ritschel 2007's Table 1 (coherent shadow maps): compression of the scanned meshes at 32x32 and
# 128x128 views, M = 128, scan-line and Hilbert (docs/coherent.md; ~15 minutes on 2 cores).
coherent-table: meshes
	@scripts/coherent_table.sh $(BUILD)

# The launch-shape tests and the small kernel tests under Oclgrind (scripts/oclgrind-check.sh;
# slow, not part of CI; docs/gpu.md, "Launch shapes").
oclgrind: build
	@scripts/oclgrind-check.sh $(BUILD)

# The C++ layout (.clang-format): format rewrites the tracked C++ files, format-check fails when
# one differs (CI).
CLANG_FORMAT ?= clang-format
FORMAT_SRC = $(shell git ls-files '*.cpp' '*.hpp')
format: deps-dev
	@$(CLANG_FORMAT) -i $(FORMAT_SRC)
format-check: deps-dev
	@$(CLANG_FORMAT) --dry-run --Werror $(FORMAT_SRC) && echo "format: $(words $(FORMAT_SRC)) files as .clang-format lays them out"

clean:
	rm -rf $(BUILD) $(BUILD).configure.log $(SANITIZE_BUILD) $(SANITIZE_BUILD).configure.log \
	    $(FUZZ_BUILD) $(FUZZ_BUILD).configure.log

# The README's commands on a new machine (as root): a clean Debian bookworm root with only make,
# g++, cmake, git and ca-certificates, a clone of HEAD, then make deps, build, test and run in it.
fresh-check:
	scripts/fresh-check.sh .
