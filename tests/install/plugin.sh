#!/usr/bin/env bash
# plugin.sh RL PLUGIN TMP_DIR: a renderer from outside renderlab in the rl
# tool (`rl --plugin`, apps/rl/plugin.c): the example plugin's "eyelight"
# (examples/custom_renderer.c) is listed, renders with its own options and
# is measured by `rl compare` beside a built-in; a file that is no plugin
# is a clean error.
set -euo pipefail
rl=${1:?usage: plugin.sh RL PLUGIN TMP}
plugin=${2:?}; tmp=${3:?}
rm -rf "$tmp"
mkdir -p "$tmp"
fail() { echo "plugin: $*" >&2; exit 1; }

# Into files first: grep -q stops reading at its match, and with pipefail
# the SIGPIPE that rl may then take would fail the test.
"$rl" --plugin "$plugin" algos > "$tmp/algos_with" || fail "rl --plugin algos failed"
"$rl" algos > "$tmp/algos_without" || fail "rl algos failed"
grep -q eyelight "$tmp/algos_with" || fail "rl algos does not list the plugin's renderer"
grep -q eyelight "$tmp/algos_without" && fail "eyelight listed without the plugin"
"$rl" -q render cornell --algo eyelight --set eyelight.ambient=0.3 --size 64x48 --out "$tmp/e.png" \
  --plugin="$plugin" > /dev/null
[ -s "$tmp/e.png" ] || fail "no image from the plugin's renderer"
# Its option table is checked like a built-in's.
if "$rl" --plugin "$plugin" render cornell --algo eyelight --set ambient=2 --out "$tmp/x.png" 2> "$tmp/err"; then
  fail "an out-of-range option of the plugin's renderer was accepted"
fi
grep -q "ambient" "$tmp/err" || fail "the message does not name the option: $(cat "$tmp/err")"

"$rl" -q --plugin "$plugin" compare cornell --algos eyelight,raster --reference whitted --samples 6 \
  --size 24x24 --repeats 1 --resolution 16 --out "$tmp/cmp" > /dev/null
grep -q '"eyelight' "$tmp/cmp/compare.json" || fail "rl compare did not measure the plugin's renderer"

# Not a plugin: one error line, exit 1.
set +e
"$rl" --plugin "$tmp/missing.so" algos > /dev/null 2> "$tmp/err"; code=$?
set -e
[ "$code" -eq 1 ] || fail "a missing plugin exits $code, not 1"
grep -q "^rl: error: --plugin" "$tmp/err" || fail "unexpected message: $(cat "$tmp/err")"
echo "plugin: eyelight listed, rendered and compared through rl --plugin"
