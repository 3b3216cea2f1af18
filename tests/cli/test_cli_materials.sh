#!/usr/bin/env bash
# test_cli_materials.sh: issue 37's materials and environment on the command
# line: the example scene renders with pt, bdpt (both lit by its sky, with
# and without GGX energy compensation) and whitted (which shows the sky),
# gl-pt renders it too (GGX ported), the sky and Schlick's Fresnel (the
# scene with its GGX spheres made Phong), and refuses light paths to GGX
# materials with one error line naming the material,
# and a scene whose environment file is missing or not an image fails with
# the file's name and position.
# Run as: bash test_cli_materials.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

SCENE="$(dirname "${BASH_SOURCE[0]}")/../../scenes/materials/materials.json"

run_ok "$RL" render "$SCENE" --algo pt --size 32x18 --spp 2 --out "$TMP/pt.exr"
[ -s "$TMP/pt.exr" ] || fail "pt wrote no image"
expect_in "$TMP/out" "^pt 32x18 .*materials.json"
run_ok "$RL" render "$SCENE" --algo whitted --size 32x18 --out "$TMP/whitted.png"
run_ok "$RL" render "$SCENE" --algo pt --set pt.env_sampling=uniform --size 16x9 --spp 1 --out "$TMP/u.exr"
expect_usage_error "$RL" render "$SCENE" --algo pt --set pt.env_sampling=cosine --size 16x9 --out "$TMP/none.png"

run_ok "$RL" render "$SCENE" --algo bdpt --size 16x9 --spp 1 --out "$TMP/bdpt.exr"
[ -s "$TMP/bdpt.exr" ] || fail "bdpt wrote no image"
run_ok "$RL" render "$SCENE" --algo pt --set pt.ggx_ms=false --size 16x9 --spp 1 --out "$TMP/single.exr"
expect_usage_error "$RL" render "$SCENE" --algo bdpt --set bdpt.ggx_ms=maybe --size 16x9 --out "$TMP/none.png"
if ! grep -A3 '^gl-pt: ' <("$RL" algos) | grep -q "unavailable:"; then
    run_ok "$RL" render "$SCENE" --algo gl-pt --size 16x9 --spp 1 --out "$TMP/gl-ggx.exr"
    [ -s "$TMP/gl-ggx.exr" ] || fail "gl-pt wrote no image of the GGX scene"
    SKY="$(cd "$(dirname "$SCENE")" && pwd)/sky.hdr"
    cat > "$TMP/phong.json" <<JSON
{ "environment": { "file": "$SKY", "rotation_deg": 30 },
  "materials": { "glass": { "diffuse": 0, "transmissivity": 1, "ior": 1.5, "fresnel": "schlick" },
                 "chrome": { "diffuse": 0, "specular": [0.55, 0.56, 0.55], "reflectivity": 1, "fresnel": "schlick" } },
  "objects": [ { "generator": "sphere", "material": "glass" },
               { "generator": "sphere", "material": "chrome", "transform": { "translate": [2.2, 0, 0] } } ] }
JSON
    run_ok "$RL" render "$TMP/phong.json" --algo gl-pt --set gl-pt.env_sampling=uniform --size 16x9 --spp 1 \
        --out "$TMP/gl.exr"
    [ -s "$TMP/gl.exr" ] || fail "gl-pt wrote no image"
    expect_usage_error "$RL" render "$TMP/phong.json" --algo gl-pt --set gl-pt.env_sampling=cosine --size 16x9 \
        --out "$TMP/none.png"
    cat > "$TMP/ggx.json" <<'JSON'
{ "materials": { "rough": { "bsdf": "ggx", "roughness": 0.5 } },
  "objects": [ { "generator": "sphere", "material": "rough" } ],
  "lights": [ { "type": "quad", "position": [-0.5, 3, -0.5], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1],
                "intensity": 10 } ] }
JSON
    # Hybrid light paths join GGX vertices (no longer refused); the means
    # against pt are tests/gl/test_gl_pt_hybrid.c's.
    run_ok "$RL" render "$TMP/ggx.json" --algo gl-pt --set gl-pt.light_paths=16 --size 16x9 --spp 1 \
        --out "$TMP/ggx.png"
    [ -s "$TMP/ggx.png" ] || fail "gl-pt with light paths and GGX wrote no image"
fi

printf '{ "environment": { "file": "nosuch.exr" },\n  "objects": [ { "generator": "box" } ] }\n' > "$TMP/missing.json"
expect_error 1 "missing.json:1:.*nosuch.exr" "$RL" render "$TMP/missing.json" --algo pt --size 8x8 --spp 1 \
    --out "$TMP/none.png"
printf 'not an image' > "$TMP/junk.hdr"
printf '{ "environment": { "file": "junk.hdr" },\n  "objects": [ { "generator": "box" } ] }\n' > "$TMP/junk.json"
expect_error 1 "junk.hdr" "$RL" render "$TMP/junk.json" --algo pt --size 8x8 --spp 1 --out "$TMP/none.png"
echo "ok"
