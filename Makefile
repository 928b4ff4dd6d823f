# Entry points named in the README. Each target installs what it needs.
PYTHON ?= python3
BUILD_DIR ?= build
JOBS ?= $(shell nproc)

.PHONY: deps build test test-native test-python demo clean

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=$$(command -v $(PYTHON)) >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test-native: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-python: build
	$(PYTHON) -m pytest -q tests/python

test: test-native test-python

demo: build
	@scripts/demo.sh

clean:
	rm -rf $(BUILD_DIR) dist
