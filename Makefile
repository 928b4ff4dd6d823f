# Entry points named in the README. Each target installs what it needs.
PYTHON ?= python3
BUILD_DIR ?= build
JOBS ?= $(shell nproc)

.PHONY: deps build test test-native test-python test-blender demo clean wheel package

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=$$(command -v $(PYTHON)) >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test-native: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-python: build
	$(PYTHON) -m pytest -q tests/python

# The add-on suite in Debian's Blender 3.4 and in bpy 4.2 (scripts/install-blender.sh installs both).
test-blender: build
	@scripts/test-blender.sh

test: test-native test-python test-blender

demo: build
	@scripts/demo.sh

# Packaging: the relief_snake_core wheel, and the two add-on zips (legacy + 4.2 extension) in dist/.
wheel: deps
	@PYTHON=$(PYTHON) scripts/build-wheel.sh

package: deps
	@PYTHON=$(PYTHON) scripts/package.sh

clean:
	rm -rf $(BUILD_DIR) dist build-wheel build-package
