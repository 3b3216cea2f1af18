#!/usr/bin/env bash
# test_cli_usage.sh: help texts, the version, the scene list and exit code 2
# for every kind of bad usage (rl's exit codes are part of its interface).
# Run as: bash test_cli_usage.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# Help: top level and every subcommand print usage, options and an example.
for h in --help -h help; do
    expect_exit 0 "$RL" "$h"
    for c in scenes algos info render demo; do expect_in "$TMP/out" "$c"; done
done
for c in scenes algos renderers info render demo; do
    expect_exit 0 "$RL" "$c" --help
    expect_in "$TMP/out" "usage: rl"
    expect_in "$TMP/out" "example"
done
expect_exit 0 "$RL" help render
expect_in "$TMP/out" "--stats-json"
expect_exit 0 "$RL" render --help
for o in --out --algo --size --camera --eye --target --up --fov --set --depth-out --id-out --stats-json; do
    expect_in "$TMP/out" "$o"
done
expect_exit 0 "$RL" --version
expect_in "$TMP/out" "renderlab"

# Lists come from the library's registries.
expect_exit 0 "$RL" scenes
for s in cornell cornell-teapot spheres city; do
    grep -q "^$s: " "$TMP/out" || fail "rl scenes does not list $s"
done
# Parameters print like renderer options: type, default, integer ranges.
expect_in "$TMP/out" "blocks  *int  *default 6 .*\[1\.\.64\]"
expect_in "$TMP/out" "furniture  *bool  *default true"
expect_exit 0 "$RL" algos
expect_in "$TMP/out" "^raster"
expect_in "$TMP/out" "shading"
expect_exit 0 "$RL" renderers
expect_in "$TMP/out" "^raster"

# Global flags work before and after the subcommand.
expect_exit 0 "$RL" -q scenes
expect_exit 0 "$RL" scenes -v

# Bad usage: exit 2 with one error line.
OUT="$TMP/u.png"
expect_usage_error "$RL"
expect_usage_error "$RL" frobnicate
expect_usage_error "$RL" --frobnicate
expect_usage_error "$RL" scenes --frobnicate
expect_usage_error "$RL" render cornell --out "$OUT" --frobnicate
expect_usage_error "$RL" render cornell --out "$OUT" extra-argument
expect_usage_error "$RL" render cornell
expect_usage_error "$RL" render --out "$OUT"
expect_usage_error "$RL" render cornell --out
expect_usage_error "$RL" render cornell --out "$OUT" --algo no-such-algo
expect_in "$TMP/err" "no-such-algo"
expect_usage_error "$RL" render cornell --out "$OUT" --set no.such.option=1
expect_usage_error "$RL" render cornell --out "$OUT" --set raster.shading=no-such-shading
expect_usage_error "$RL" render cornell --out "$OUT" --set missing-equals
expect_usage_error "$RL" render cornell --out "$OUT" --size 64
expect_usage_error "$RL" render cornell --out "$OUT" --size 64xfoo
expect_usage_error "$RL" render cornell --out "$OUT" --size -4x4
expect_usage_error "$RL" render cornell --out "$OUT" --size 0x0
expect_in "$TMP/err" "0x0"
expect_usage_error "$RL" render cornell --out "$OUT" --size 20000x20000
expect_usage_error "$RL" render cornell --out "$OUT" --size 16385x1
expect_usage_error "$RL" render cornell --out "$OUT" --eye 1,2
expect_usage_error "$RL" render cornell --out "$OUT" --eye 1,2,nan
expect_usage_error "$RL" render cornell --out "$OUT" --up 1,2,3,4
expect_usage_error "$RL" render cornell --out "$OUT" --eye 1,1,1 --target 1,1,1
expect_usage_error "$RL" render cornell --out "$OUT" --fov 0
expect_usage_error "$RL" render cornell --out "$OUT" --fov 200
expect_usage_error "$RL" render cornell --out "$TMP/u.bmp"
expect_usage_error "$RL" render cornell-teapot:no_such_param=1 --out "$OUT"
expect_in "$TMP/err" "no_such_param"
expect_usage_error "$RL" render cornell-teapot:triangles=-5 --out "$OUT"
expect_usage_error "$RL" info
expect_usage_error "$RL" info cornell --frobnicate
expect_usage_error "$RL" demo --out "$TMP/d" --scenes no-such-scene
expect_usage_error "$RL" demo --out "$TMP/d" --size 0x0
# Nothing was rendered by any of the above.
[ ! -e "$OUT" ] || fail "a usage error still wrote $OUT"
echo "ok"
