# Thin wrapper around CMake; see README.md.
BUILD      ?= build
BUILD_SAN  ?= build-asan
BUILD_FUZZ ?= build-fuzz
BUILD_INSTALL ?= build-install
PREFIX     ?= /usr/local
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=

.PHONY: all deps build build-asan build-fuzz fuzz check demo install clean

all: build

deps:
	@bash scripts/install-deps.sh

build:
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

build-asan:
	@cmake -S . -B $(BUILD_SAN) -DCMAKE_BUILD_TYPE=Debug -DRL_SANITIZE=ON $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD_SAN) -j $(JOBS)

# The libFuzzer harnesses with clang (instrumented library, ASan+UBSan).
FUZZ_SCALE   ?= 1
FUZZ_SECONDS ?= 60
FUZZ_TARGETS  = fuzz_load_json fuzz_load_mesh fuzz_approx fuzz_linespace_cache fuzz_texture fuzz_options
build-fuzz:
	@CC=clang CXX=clang++ cmake -S . -B $(BUILD_FUZZ) -DCMAKE_BUILD_TYPE=Debug -DRL_SANITIZE=ON -DRL_FUZZ=ON \
	    -DRL_TESTS=OFF -DRL_WERROR=OFF -DRL_FUZZ_SCALE=$(FUZZ_SCALE) $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD_FUZZ) -j $(JOBS) --target $(FUZZ_TARGETS)

# A longer campaign: every harness for FUZZ_SECONDS on its corpus, which
# keeps what it finds (tests/fuzz/corpus/<kind>); crashes go to
# tests/fuzz/crashes/<kind>-* as regression inputs. A harness that crashes
# does not stop the others; the target fails at the end if any did.
# Leaks are not checked for meshes, where Assimp leaks. Each input passes
# through a file in /dev/shm (RL_FUZZ_TMPDIR to choose another folder;
# tests/fuzz/fuzz_temp.h says why).
FUZZ_FLAGS = -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=30 -rss_limit_mb=4096 -print_final_stats=1
fuzz: build-fuzz
	@mkdir -p tests/fuzz/crashes
	@fails=0; f=$(BUILD_FUZZ)/tests/fuzz; c=tests/fuzz/corpus; a=tests/fuzz/crashes; \
	$$f/fuzz_load_json $(FUZZ_FLAGS) -artifact_prefix=$$a/json- $$c/json || fails=$$((fails + 1)); \
	ASAN_OPTIONS=detect_leaks=0 $$f/fuzz_load_mesh $(FUZZ_FLAGS) -detect_leaks=0 -artifact_prefix=$$a/mesh- \
	    $$c/mesh || fails=$$((fails + 1)); \
	$$f/fuzz_approx $(FUZZ_FLAGS) -artifact_prefix=$$a/approx- $$c/approx || fails=$$((fails + 1)); \
	$$f/fuzz_linespace_cache $(FUZZ_FLAGS) -max_len=16384 -artifact_prefix=$$a/linespace- $$c/linespace || fails=$$((fails + 1)); \
	$$f/fuzz_texture $(FUZZ_FLAGS) -artifact_prefix=$$a/texture- $$c/texture || fails=$$((fails + 1)); \
	$$f/fuzz_options $(FUZZ_FLAGS) -close_fd_mask=3 -dict=tests/fuzz/options.dict \
	    -artifact_prefix=$$a/options- $$c/options || fails=$$((fails + 1)); \
	if [ $$fails -ne 0 ]; then echo "fuzz: $$fails harness(es) found a crash: see tests/fuzz/crashes/"; exit 1; fi

# Release tests, then the same tests under ASan+UBSan, then a short smoke
# run of every fuzz harness (where clang is installed).
check: deps
	@$(MAKE) --no-print-directory build
	@$(MAKE) --no-print-directory build-asan
	@echo "== ctest: Release ($(BUILD)) =="
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	@echo "== ctest: ASan+UBSan Debug ($(BUILD_SAN)) =="
	@cd $(BUILD_SAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	    ctest --output-on-failure -j $(JOBS)
	@if command -v clang >/dev/null 2>&1; then \
	    echo "== fuzz smoke: libFuzzer, clang, ASan+UBSan ($(BUILD_FUZZ)) =="; \
	    $(MAKE) --no-print-directory build-fuzz && cd $(BUILD_FUZZ) && ctest --output-on-failure -j $(JOBS); \
	else echo "== fuzz smoke: skipped (no clang) =="; fi

# Headers, libraries (shared and static), rl, renderlab.pc and the CMake
# package under $(DESTDIR)$(PREFIX). Built apart from build/, without
# -march=native (the result may run elsewhere), the tests and -Werror.
install:
	@cmake -S . -B $(BUILD_INSTALL) -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=$(PREFIX) -DRL_NATIVE=OFF \
	    -DRL_TESTS=OFF -DRL_EXAMPLES=OFF -DRL_WERROR=OFF $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD_INSTALL) -j $(JOBS)
	@DESTDIR=$(DESTDIR) cmake --install $(BUILD_INSTALL)

demo: deps build
	@$(BUILD)/rl demo --out out/demo
	@# The viewer's window, drawn without a display by SDL's offscreen driver.
	@SDL_VIDEODRIVER=offscreen $(BUILD)/rl view table --algo vt --size 640x480 \
		--script scripts/demo-view.txt && echo "demo: out/demo/viewer.png (rl view)" || \
		echo "demo: no viewer screenshot (rl view failed, see above)"

clean:
	rm -rf $(BUILD) $(BUILD_SAN) $(BUILD_FUZZ) $(BUILD_INSTALL) out
