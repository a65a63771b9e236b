# drape: the two commands are `make demo` and `make test`.
#   make build   install missing Debian packages, build the optimised binary build/release/drape
#   make demo    build, then run the bundled example and print where its results are
#   make test    install, build with AddressSanitizer + UBSan (build/asan), run the tests with CTest;
#                then build as `make build` does, tests included (build/native), and run them again
#                (the longest scenarios run in this second half only: docs/ARCHITECTURE.md)
#   make fuzz    build the libFuzzer targets with clang and run each for FUZZ_SECONDS (default 60)
#   make bench   run every benchmark on the optimised build and print their JSON

SHELL := /bin/bash
JOBS ?= $(shell nproc)
RELEASE_DIR := build/release
ASAN_DIR := build/asan
NATIVE_DIR := build/native
FUZZ_DIR := build/fuzz
FUZZ_SECONDS ?= 60
DEMO_OUT ?= out/walking_skirt

.PHONY: deps build demo test fuzz bench clean

deps:
	@scripts/install-deps

build: deps
	@cmake -S . -B $(RELEASE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release -DDRAPE_NATIVE=ON -DDRAPE_BUILD_TESTS=OFF >/dev/null
	@cmake --build $(RELEASE_DIR) -j $(JOBS)
	@echo "built $(RELEASE_DIR)/drape"

demo: build
	@scripts/demo $(RELEASE_DIR)/drape $(DEMO_OUT)

test: deps
	@cmake -S . -B $(ASAN_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDRAPE_SANITIZE=ON >/dev/null
	@cmake --build $(ASAN_DIR) -j $(JOBS)
	@cd $(ASAN_DIR) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
		ctest --output-on-failure -j $(JOBS)
	@echo "the suite again in $(NATIVE_DIR), optimised for this machine as $(RELEASE_DIR) is (its vector and fused multiply-add paths)"
	@cmake -S . -B $(NATIVE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release -DDRAPE_NATIVE=ON -DDRAPE_BUILD_TESTS=ON >/dev/null
	@cmake --build $(NATIVE_DIR) -j $(JOBS)
	@cd $(NATIVE_DIR) && ctest --output-on-failure -j $(JOBS)

fuzz: deps
	@CC=clang CXX=clang++ cmake -S . -B $(FUZZ_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDRAPE_FUZZ=ON -DDRAPE_BUILD_TESTS=OFF >/dev/null
	@cmake --build $(FUZZ_DIR) -j $(JOBS)
	@scripts/run-fuzzers $(FUZZ_DIR) $(FUZZ_SECONDS)

bench: build
	@for b in $$($(RELEASE_DIR)/drape bench --help | awk '/^Subcommands:/{s=1;next} s && !NF {exit} s {print $$1}'); do \
		echo "== drape bench $$b --json" >&2; $(RELEASE_DIR)/drape bench $$b --json; done

clean:
	rm -rf build out
