# Thin entry points; the build itself is CMake (see CMakeLists.txt).
BUILD ?= build
JOBS ?= $(shell nproc)

.PHONY: setup build demo test bench clean

setup:
	scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# Renders the built-in scene, fogs it on PoCL and on the scalar path, writes out/demo/*.exr|png.
demo: build
	$(BUILD)/src/fogcl demo --out out/demo

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

bench: build
	$(BUILD)/bench/fogcl_bench

clean:
	rm -rf $(BUILD) out
