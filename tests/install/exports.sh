#!/usr/bin/env bash
# exports.sh LIBRENDERLAB.so INCLUDE_DIR: the shared library exports
# exactly the functions its public headers declare RL_API, so that the
# internal rl_* helpers of src/ (hidden visibility, rl_common.h) stay
# private and an application cannot come to depend on them.
set -uo pipefail
lib=${1:?usage: exports.sh LIB INCLUDE_DIR}
inc=${2:?usage: exports.sh LIB INCLUDE_DIR}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Defined dynamic symbols, without version suffixes and the linker's own.
nm -D --defined-only "$lib" | awk '{ print $NF }' | sed 's/@.*//' |
  grep -vxE '_init|_fini|_edata|_end|__bss_start' | sort -u > "$tmp/exported"
# The name of every RL_API declaration: the first identifier before "(".
cat "$inc"/rl/*.h | grep -v '^#' | perl -0pe 's{/\*.*?\*/}{}gs' | tr '\n' ' ' | grep -oE 'RL_API[^;(]*\(' |
  grep -oE '[A-Za-z_][A-Za-z0-9_]*[[:space:]]*\($' | tr -d '( ' | sort -u > "$tmp/declared"

fails=0
if grep -v '^rl_' "$tmp/exported" > "$tmp/foreign"; then
  echo "exports: symbols without the rl_ prefix:"; head -20 "$tmp/foreign"; fails=1
fi
if comm -23 "$tmp/exported" "$tmp/declared" | grep -q .; then
  echo "exports: exported but not declared RL_API in include/rl (internal helpers leak):"
  comm -23 "$tmp/exported" "$tmp/declared" | head -20; fails=1
fi
if comm -13 "$tmp/exported" "$tmp/declared" | grep -q .; then
  echo "exports: declared RL_API but not exported:"
  comm -13 "$tmp/exported" "$tmp/declared" | head -20; fails=1
fi
[ "$fails" -eq 0 ] || exit 1
echo "exports: $(wc -l < "$tmp/exported") symbols, all rl_*, exactly the RL_API declarations"
