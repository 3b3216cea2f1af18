# Thin wrapper around CMake; see README.md.
BUILD      ?= build
BUILD_SAN  ?= build-asan
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=

.PHONY: all deps build build-asan check demo clean

all: build

deps:
	@bash scripts/install-deps.sh

build:
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

build-asan:
	@cmake -S . -B $(BUILD_SAN) -DCMAKE_BUILD_TYPE=Debug -DRL_SANITIZE=ON $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD_SAN) -j $(JOBS)

# Release tests, then the same tests under ASan+UBSan.
check: deps
	@$(MAKE) --no-print-directory build
	@$(MAKE) --no-print-directory build-asan
	@echo "== ctest: Release ($(BUILD)) =="
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	@echo "== ctest: ASan+UBSan Debug ($(BUILD_SAN)) =="
	@cd $(BUILD_SAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	    ctest --output-on-failure -j $(JOBS)

demo: deps build
	@$(BUILD)/rl demo --out out/demo

clean:
	rm -rf $(BUILD) $(BUILD_SAN) out
