#!/usr/bin/env bash
# check_layers.sh SOURCE_DIR C_COMPILER: the include rules of the
# architecture (README, "Layout"), checked on every file of the tree.
#
#   1. Layers run one way: core < scene < accel, raster < gl < render <
#      eval < dist < apps. A file of src/<module>/ includes headers of its
#      own module or of lower layers only, public (include/rl/) or not;
#      accel and raster, side by side, do not include each other.
#   2. apps/ sees only include/rl/ (and its own headers).
#   3. A public header includes public headers of its own layer or lower.
#   4. Every public header compiles on its own.
#   5. rl.h includes every public header, and no library file includes rl.h.
#
# Prints one line per broken rule and fails if there is any.
set -uo pipefail
src=${1:?usage: check_layers.sh SOURCE_DIR C_COMPILER}
cc=${2:?usage: check_layers.sh SOURCE_DIR C_COMPILER}
cd "$src" || exit 2

# Rank of each module; equal ranks of different modules may not meet.
declare -A rank=([core]=0 [scene]=1 [accel]=2 [raster]=2 [gl]=3 [render]=4 [eval]=5 [dist]=6 [apps]=7)

# The layer of each public header: the module that implements it. A new
# header must be added here, so that it is placed on purpose.
declare -A header=(
  [rl_common.h]=core [rl_options.h]=core [rl_path.h]=core [rl_math.h]=core [rl_rng.h]=core
  [rl_image.h]=core [rl_timer.h]=core [rl_output.h]=core
  [rl_camera.h]=scene [rl_scene.h]=scene [rl_octree.h]=scene
  [rl_accel.h]=accel [rl_linespace.h]=accel
  [rl_raster.h]=raster [rl_drawer.h]=raster [rl_shadowmap.h]=raster
  [rl_gl.h]=gl
  [rl_render.h]=render [rl_trace.h]=render [rl_gbuffer.h]=render [rl_filter.h]=render [rl_pt.h]=render
  [rl_vt.h]=render [rl_culling.h]=render [rl_surfels.h]=render
  [rl_property.h]=eval [rl_sampling.h]=eval [rl_metrics.h]=eval [rl_stats.h]=eval [rl_plot.h]=eval
  [rl_dist.h]=dist
)

fails=0
fail() { echo "layers: $*"; fails=$((fails + 1)); }

# may_include FROM TO: whether module FROM may include module TO.
may_include() {
  local from=$1 to=$2
  [ "$from" = "$to" ] && return 0
  [ -n "${rank[$to]:-}" ] || return 1
  [ "${rank[$to]}" -lt "${rank[$from]}" ]
}

# The quoted includes of a file, one per line.
includes() { sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$1"; }

for f in include/rl/*.h; do
  h=$(basename "$f")
  [ "$h" = rl.h ] && continue
  [ -n "${header[$h]:-}" ] || { fail "$f: not placed in a layer (add it to tests/arch/check_layers.sh)"; continue; }
done

# Rules 1 and 5: the library.
for f in $(find src -name '*.[ch]' -o -name '*.cpp' | sort); do
  m=$(echo "$f" | cut -d/ -f2)
  [ -n "${rank[$m]:-}" ] || { fail "$f: module src/$m is not a layer"; continue; }
  while IFS= read -r inc; do
    [ -z "$inc" ] && continue
    case "$inc" in
      rl/rl.h) fail "$f: includes rl/rl.h (the umbrella is for applications)" ;;
      rl/*)
        h=${inc#rl/}
        to=${header[$h]:-}
        if [ -z "$to" ]; then fail "$f: includes $inc, which is no public header"
        elif ! may_include "$m" "$to"; then fail "$f: $m includes $inc of layer $to"; fi ;;
      */*)
        to=${inc%%/*}
        may_include "$m" "$to" || fail "$f: $m includes $inc of layer $to" ;;
      *)
        [ -e "$(dirname "$f")/$inc" ] || fail "$f: includes \"$inc\", not beside it" ;;
    esac
  done < <(includes "$f")
done

# Rule 2: the CLI.
for f in $(find apps -name '*.[ch]' | sort); do
  while IFS= read -r inc; do
    [ -z "$inc" ] && continue
    case "$inc" in
      rl/*) [ -e "include/$inc" ] || fail "$f: includes $inc, which is no public header" ;;
      */*) fail "$f: includes $inc (apps see only include/rl)" ;;
      *) [ -e "$(dirname "$f")/$inc" ] || fail "$f: includes \"$inc\", not beside it" ;;
    esac
  done < <(includes "$f")
done

# Rules 3 and 4: public headers.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for f in include/rl/*.h; do
  h=$(basename "$f")
  m=${header[$h]:-apps}
  while IFS= read -r inc; do
    [ -z "$inc" ] && continue
    case "$inc" in
      rl/*)
        to=${header[${inc#rl/}]:-}
        [ "$h" = rl.h ] && continue
        if [ -z "$to" ]; then fail "$f: includes $inc, which is no layered public header"
        elif ! may_include "$m" "$to"; then fail "$f: a $m header includes $inc of layer $to"; fi ;;
      *) fail "$f: includes \"$inc\" (public headers include only rl/ headers)" ;;
    esac
  done < <(includes "$f")
  printf '#include "rl/%s"\n' "$h" > "$tmp/one.c"
  if ! out=$("$cc" -std=c11 -Wall -Wextra -Werror -fsyntax-only -Iinclude "$tmp/one.c" 2>&1); then
    fail "$f: does not compile on its own:"
    echo "$out" | head -5
  fi
done

for f in include/rl/*.h; do
  h=$(basename "$f")
  [ "$h" = rl.h ] && continue
  grep -q "^#include \"rl/$h\"" include/rl/rl.h || fail "include/rl/rl.h: does not include rl/$h"
done

if [ "$fails" -gt 0 ]; then
  echo "layers: $fails broken rule(s)"
  exit 1
fi
echo "layers: every include runs one way; $(ls include/rl/*.h | wc -l) public headers compile on their own"
