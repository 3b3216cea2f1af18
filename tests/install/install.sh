#!/usr/bin/env bash
# install.sh BUILD_DIR SOURCE_DIR TMP_DIR C_COMPILER CMAKE: renderlab as a
# dependency. Installs the build into a temporary prefix and builds
# examples against the installed copy only, as a user would:
#   1. pkg-config, shared library (the default);
#   2. pkg-config --static, the static library and its private deps;
#   3. CMake, find_package(renderlab COMPONENTS static): both targets;
#   4. add_subdirectory: a subproject configures without -march=native,
#      tests and -Werror (configure only: building it again costs minutes).
# Every program built is run.
set -euo pipefail
build=${1:?usage: install.sh BUILD SOURCE TMP CC CMAKE}
src=${2:?}; tmp=${3:?}; cc=${4:?}; cmake=${5:?}
src=$(cd "$src" && pwd)
rm -rf "$tmp"
mkdir -p "$tmp"
tmp=$(cd "$tmp" && pwd)
prefix=$tmp/prefix
fail() { echo "install: $*" >&2; exit 1; }

"$cmake" --install "$build" --prefix "$prefix" > "$tmp/install.log" 2>&1 ||
  { cat "$tmp/install.log"; fail "cmake --install failed"; }
pc=$(find "$prefix" -name renderlab.pc)
[ -n "$pc" ] || fail "no renderlab.pc installed"
libdir=$(dirname "$(dirname "$pc")")
for f in "$prefix/bin/rl" "$prefix/include/rl/rl.h" "$prefix/include/rl/rl_render.h" "$libdir/librenderlab.a" \
         "$libdir/librenderlab.so" "$libdir/cmake/renderlab/renderlab-config.cmake"; do
  [ -e "$f" ] || fail "$f not installed"
done
"$prefix/bin/rl" --version > /dev/null || fail "the installed rl does not run"

# 1. pkg-config, shared: nothing else on the link line.
export PKG_CONFIG_PATH=$libdir/pkgconfig
[ "$(pkg-config --modversion renderlab)" = "$(sed -n 's/^project(renderlab VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")" ] ||
  fail "renderlab.pc has the wrong version"
# shellcheck disable=SC2046
"$cc" -std=c11 -Wall -Wextra -Werror "$src/examples/render_scene.c" -o "$tmp/pc_shared" \
  $(pkg-config --cflags --libs renderlab) -Wl,-rpath,"$libdir"
readelf -d "$tmp/pc_shared" | grep -q 'librenderlab\.so' || fail "pc_shared does not link the shared library"
"$tmp/pc_shared" "$tmp/pc_shared.png" > /dev/null
[ -s "$tmp/pc_shared.png" ] || fail "pc_shared wrote no image"

# 2. pkg-config, static: the .pc's private requirements complete the link.
libs=$(pkg-config --static --libs renderlab | sed 's/-lrenderlab/-Wl,-Bstatic -lrenderlab -Wl,-Bdynamic/')
# shellcheck disable=SC2086
"$cc" -std=c11 -Wall -Wextra -Werror "$src/examples/custom_renderer.c" -o "$tmp/pc_static" \
  $(pkg-config --cflags renderlab) $libs
if readelf -d "$tmp/pc_static" | grep -q 'librenderlab\.so'; then fail "pc_static links the shared library"; fi
mkdir -p "$tmp/pc_static.out"
"$tmp/pc_static" "$tmp/pc_static.out" > /dev/null

# 3. CMake: a consumer project with both targets.
mkdir -p "$tmp/consumer"
cat > "$tmp/consumer/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(consumer C CXX)
find_package(renderlab 0.1 REQUIRED COMPONENTS static)
add_executable(shared_example "$src/examples/render_scene.c")
target_link_libraries(shared_example PRIVATE renderlab::renderlab)
add_executable(static_example "$src/examples/evaluate_property.c")
target_link_libraries(static_example PRIVATE renderlab::renderlab_static)
CMAKE
"$cmake" -S "$tmp/consumer" -B "$tmp/consumer/build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" > "$tmp/consumer.log" 2>&1 || { cat "$tmp/consumer.log"; fail "find_package failed"; }
"$cmake" --build "$tmp/consumer/build" >> "$tmp/consumer.log" 2>&1 ||
  { cat "$tmp/consumer.log"; fail "the CMake consumer does not build"; }
readelf -d "$tmp/consumer/build/shared_example" | grep -q 'librenderlab\.so' ||
  fail "renderlab::renderlab is not the shared library"
"$tmp/consumer/build/shared_example" "$tmp/cmake_shared.png" > /dev/null
OMP_NUM_THREADS=2 "$tmp/consumer/build/static_example" > /dev/null

# 4. add_subdirectory: the parent's project, not a development build.
mkdir -p "$tmp/parent"
cat > "$tmp/parent/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(parent C CXX)
add_subdirectory("$src" renderlab)
CMAKE
"$cmake" -S "$tmp/parent" -B "$tmp/parent/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER="$cc" \
  > "$tmp/parent.log" 2>&1 || { cat "$tmp/parent.log"; fail "renderlab does not configure as a subproject"; }
for opt in RL_NATIVE RL_TESTS RL_WERROR RL_EXAMPLES; do
  grep -q "^$opt:BOOL=OFF" "$tmp/parent/build/CMakeCache.txt" || fail "$opt is not off in a subproject"
done
if grep -rq -- '-march=native' "$tmp/parent/build/renderlab/CMakeFiles"; then
  fail "a subproject compiles with -march=native"
fi
echo "install: pkg-config (shared, static), find_package (shared, static) and add_subdirectory all work"
