# Entry points named in the README. Each target installs what it needs.
PYTHON ?= python3
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
# Warnings are errors in `make build` (so in CI); WERROR=OFF to build past them locally.
WERROR ?= ON

.PHONY: deps build test test-native test-python test-blender test-package test-blender-ui demo clean wheel package bench bench-random fuzz fuzz-campaign

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DRELIEF_SNAKE_WERROR=$(WERROR) -DPython3_EXECUTABLE=$$(command -v $(PYTHON)) >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test-native: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-python: build
	RELIEF_SNAKE_BUILD_DIR=$(BUILD_DIR) $(PYTHON) -m pytest -q tests/python --ignore=tests/python/test_package.py

# The add-on suite in Debian's Blender 3.4, bpy 4.5 LTS and bpy 5.2 LTS (scripts/install-blender.sh installs them).
test-blender: build
	@BUILD_DIR=$(BUILD_DIR) scripts/test-blender.sh

# The packages, built as `make package` builds them (from the module in $(BUILD_DIR)) into
# $(BUILD_DIR)/dist, unpacked, imported and installed in both Blenders. Missing packages or
# Blenders fail these tests here instead of skipping them.
test-package: build
	@PYTHON=$(PYTHON) BUILD_DIR=$(BUILD_DIR) JOBS=$(JOBS) DIST=$(BUILD_DIR)/dist STAGE=$(BUILD_DIR)/package-stage scripts/package.sh
	RELIEF_SNAKE_DIST=$(BUILD_DIR)/dist RELIEF_SNAKE_REQUIRE_PACKAGES=1 $(PYTHON) -m pytest -q tests/python/test_package.py

# Real-window tests: Blender 3.4 on Xvfb driven by xdotool, installing the legacy zip that
# test-package built; screenshots and logs in $(BUILD_DIR)/blender-ui-artifacts.
test-blender-ui: test-package
	$(PYTHON) tests/blender/ui/harness.py --zip $(BUILD_DIR)/dist/relief_snake-$$(sed -n 's/^version = "\(.*\)"$$/\1/p' pyproject.toml | head -1)-legacy.zip \
	  --build-dir $(BUILD_DIR) --out $(BUILD_DIR)/blender-ui-artifacts

test: test-native test-python test-blender test-package test-blender-ui

demo: build
	@scripts/demo.sh

# The benchmark (issue 4): bench/results/report.md and plots; and the randomized suite (issue 14,
# 200 random scans): bench/results/random/report.md. Builds only what it runs.
bench: deps
	@BUILD_DIR=$(BUILD_DIR) PYTHON=$(PYTHON) JOBS=$(JOBS) scripts/bench.sh

# The randomized suite alone (RANDOM_SEEDS, RANDOM_ARGS: see scripts/bench.sh).
bench-random: deps
	@BUILD_DIR=$(BUILD_DIR) PYTHON=$(PYTHON) JOBS=$(JOBS) BENCH_SECTIONS=random scripts/bench.sh

# Fuzzing (issue 11): the libFuzzer targets under ASan+UBSan, FUZZ_SECONDS each (clang from Debian).
# A finding fails; its input is left in $(FUZZ_DIR)/findings/ to be added to fuzz/regression/.
FUZZ_SECONDS ?= 60
FUZZ_DIR ?= build-fuzz
fuzz: build
	@PYTHON=$(PYTHON) scripts/install-fuzz-deps.sh
	@FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_DIR=$(FUZZ_DIR) BUILD_DIR=$(BUILD_DIR) JOBS=$(JOBS) PYTHON=$(PYTHON) scripts/fuzz.sh

# A fuzzing campaign (issue 11 asks for 10^6 executions per target): the libFuzzer targets only, one
# after the other on one core at nice 10, CAMPAIGN_SECONDS each, growing the corpus kept in
# $(FUZZ_DIR)/corpus; then the totals of every run so far ($(FUZZ_DIR)/campaign.log, `make fuzz` too).
CAMPAIGN_SECONDS ?= 900
FUZZ_TARGETS ?= mesh_intake segment
fuzz-campaign: deps
	@PYTHON=$(PYTHON) scripts/install-fuzz-deps.sh
	@FUZZ_SECONDS=$(CAMPAIGN_SECONDS) FUZZ_DIR=$(FUZZ_DIR) FUZZ_TARGETS="$(FUZZ_TARGETS)" FUZZ_ATHERIS=0 JOBS=1 \
	  nice -n 10 scripts/fuzz.sh
	@awk '{ e[$$2] += $$4; s[$$2] += $$3 } END { for (t in e) printf "fuzz-campaign: %s: %d executions in %d s in total\n", t, e[t], s[t] }' \
	  $(FUZZ_DIR)/campaign.log

# Packaging: the relief_snake_core wheels (cp311, cp313), the legacy zip and one extension zip per Blender Python in dist/.
wheel: deps
	@PYTHON=$(PYTHON) scripts/build-wheel.sh

package: deps
	@PYTHON=$(PYTHON) BUILD_DIR=$(BUILD_DIR) JOBS=$(JOBS) scripts/package.sh

clean:
	rm -rf $(BUILD_DIR) dist build-wheel build-package build-fuzz
