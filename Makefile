# Thin entry points; the build itself is CMake (see CMakeLists.txt).
BUILD ?= build
JOBS ?= $(shell nproc)

.PHONY: setup build demo test bench clean asan-build asan-test fuzz gpu-bundle

setup:
	scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# Renders the built-in scene, fogs it on PoCL and on the scalar path, writes out/demo/*.exr|png.
demo: build
	$(BUILD)/src/fogcl demo --out out/demo

# Ends with the count of tests that passed, failed and were skipped (with each skip's reason),
# from ctest's JUnit file; the exit status is ctest's.
test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) --output-junit junit.xml; \
	  status=$$?; python3 scripts/test_summary.py $(BUILD)/junit.xml; exit $$status

# Google Benchmark suite -> out/bench/{fog,pocl1,start-*}.json, table.md and throughput.png.
bench: build
	scripts/setup.sh --bench
	bench/run.sh $(BUILD) out/bench

# What the GPU machine needs, in out/gpu-bundle: carry it there and run its gpu-run.sh (docs/gpu.md).
gpu-bundle:
	scripts/gpu-bundle.sh $(BUILD) out/gpu-bundle

# Sanitizer build (clang): the whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer,
# and the libFuzzer targets over EXR loading and VOLUMES.json, from one build folder. Without the
# Python module: a sanitized extension cannot load into the unsanitized interpreter (`make test`
# runs its tests).
# detect_leaks=0: PoCL and the OpenCL ICD loader keep process-lifetime allocations (LLVM's JIT
# state, the platform list) that LeakSanitizer reports at exit; fogcl's own leaks would show in the
# scalar/IO tests (docs/cli.md, "Errors"). allocator_may_return_null=1: an allocation too large for
# ASan's allocator fails as it does without ASan (the misuse tests check the error it becomes).
ASAN_BUILD ?= build-asan
SANITIZE := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_SECONDS ?= 30
export ASAN_OPTIONS ?= detect_leaks=0:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS ?= print_stacktrace=1:halt_on_error=1

asan-build:
	scripts/setup.sh --sanitizers
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++-14 \
	  -DCMAKE_CXX_FLAGS_DEBUG="-O2 -g" -DCMAKE_CXX_FLAGS="$(SANITIZE) -fsanitize=fuzzer-no-link" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE)" -DCMAKE_SHARED_LINKER_FLAGS="$(SANITIZE)" \
	  -DFOGCL_BUILD_BENCH=OFF -DFOGCL_BUILD_FUZZ=ON -DFOGCL_PYTHON=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)

# Every test but the 1080p / 8K frame sizes, which under ASan run the same host code as the smaller
# sizes (the kernel itself runs in PoCL's JIT, which ASan does not instrument) at 3x the time, and
# the mutation check, which builds an unsanitized copy of its own (`make test` runs it).
# The tests that hold fogcl at a libc call (tests/support/call_gate.c, preloaded) run in `make test`
# only: the sanitizers' own interceptors of those calls come first and bypass the gate.
GATED_TESTS := SignalsLeaveNoNamedTemporary|KillDashNineMidWrite|CtrlCSaysHowManyFrames|SlurmFogShot
asan-test: asan-build
	ctest --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS) -E '1920x1080|EightK|VolumeSizeSweep|MutationCheck|$(GATED_TESTS)'

# Bounded fuzz runs (FUZZ_SECONDS each) from the generated seed corpora: EXR loading, then the
# VOLUMES.json parser (seeded with the demo's volume files); new inputs go to
# $(ASAN_BUILD)/fuzz-corpus and $(ASAN_BUILD)/fuzz-json-corpus.
fuzz: asan-build
	$(ASAN_BUILD)/fuzz/fogcl_make_seeds $(ASAN_BUILD)/fuzz-seeds $(ASAN_BUILD)/fuzz-json-seeds
	mkdir -p $(ASAN_BUILD)/fuzz-corpus $(ASAN_BUILD)/fuzz-json-corpus
	$(ASAN_BUILD)/fuzz/fogcl_exr_fuzzer -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 -timeout=10 \
	  -print_final_stats=1 $(ASAN_BUILD)/fuzz-corpus $(ASAN_BUILD)/fuzz-seeds
	$(ASAN_BUILD)/fuzz/fogcl_volumes_json_fuzzer -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 -timeout=10 \
	  -dict=fuzz/volumes_json.dict -print_final_stats=1 $(ASAN_BUILD)/fuzz-json-corpus $(ASAN_BUILD)/fuzz-json-seeds

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) out
