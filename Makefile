# The two README commands: `make run` and `make test`. Everything else is a helper.
BUILD ?= build
JOBS ?= $(shell nproc)
OUT ?= out

.PHONY: deps deps-bench configure build run test bench data clean

deps:
	@scripts/install-deps.sh core

deps-bench:
	@scripts/install-deps.sh bench

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release > $(BUILD).configure.log 2>&1 || (cat $(BUILD).configure.log; exit 1)

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Main job: ESM with a Gaussian prefilter on the bundled default scene.
run: build
	@mkdir -p $(OUT)
	$(BUILD)/shadowfilter filter --shadow-map data/spheres/shadowmap.exr \
	    --receivers data/spheres/receivers.exr -o $(OUT)/spheres_esm.exr \
	    --method esm --esm-c 80 --blur-radius 3
	$(BUILD)/shadowfilter filter --shadow-map data/spheres/shadowmap.exr \
	    --receiver-depth data/spheres/receiver_depth.exr -o $(OUT)/spheres_esm_planar.exr \
	    --method esm --esm-c 80 --blur-radius 3
	@echo "output images: $(OUT)/spheres_esm.exr (camera view), $(OUT)/spheres_esm_planar.exr (planar receiver)"

test: build
	@cd $(BUILD) && ctest --output-on-failure -j 2

bench: build deps-bench
	@cmake -S . -B $(BUILD) -DSF_BUILD_BENCH=ON > /dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target sf_bench
	@mkdir -p $(OUT)
	$(BUILD)/sf_bench --benchmark_out=$(OUT)/bench.json --benchmark_out_format=json

# Regenerates the bundled scenes in data/ (deterministic).
data: build
	$(BUILD)/sf_make_scene --out data/spheres

clean:
	rm -rf $(BUILD) $(BUILD).configure.log
