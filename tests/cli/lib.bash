# lib.bash: what every CLI integration script shares (sourced, not a test:
# ctest runs only tests/cli/*.sh). Scripts run as: bash script.sh <rl> <dir>;
# this sets RL and a fresh scratch directory TMP.
RL=$1
TMP=$2
rm -rf "$TMP"
mkdir -p "$TMP"

fail() { echo "FAIL: $*" >&2; exit 1; }
# The JSON checks are Python: never skipped (scripts/install-deps.sh installs it).
python3 -c 'import json' 2>/dev/null || fail "python3 with its json module is needed by the CLI tests"
# run_ok CMD...: runs CMD, keeps its stdout/stderr in $TMP/out, $TMP/err.
run_ok() {
    "$@" >"$TMP/out" 2>"$TMP/err" || fail "'$*' exited $?; stderr: $(head -c 400 "$TMP/err")"
}
# expect_exit CODE CMD...: runs CMD, keeps its stdout/stderr, checks the code.
expect_exit() {
    local want=$1; shift
    "$@" >"$TMP/out" 2>"$TMP/err"
    local got=$?
    [ "$got" -eq "$want" ] || fail "'$*' exited $got, expected $want; stderr: $(head -c 400 "$TMP/err")"
}
# expect_error CODE TEXT CMD...: exit CODE, one "rl: error:" line, containing TEXT.
expect_error() {
    local code=$1 text=$2; shift 2
    expect_exit "$code" "$@"
    [ "$(grep -c '^rl: error: ' "$TMP/err")" -eq 1 ] || fail "'$*' should print one error line, got: $(cat "$TMP/err")"
    grep '^rl: error: ' "$TMP/err" | grep -q -- "$text" || fail "'$*': error line lacks '$text': $(cat "$TMP/err")"
}
# expect_usage_error CMD...: exit 2 and exactly one "rl: error:" line.
expect_usage_error() {
    expect_exit 2 "$@"
    [ "$(grep -c '^rl: error: ' "$TMP/err")" -eq 1 ] || fail "'$*' should print one error line, got: $(cat "$TMP/err")"
}
# expect_in FILE TEXT: FILE contains TEXT.
expect_in() { grep -q -- "$2" "$1" || fail "$1 lacks '$2': $(head -c 400 "$1")"; }
# bounded CMD...: runs CMD with at most 30 s and, outside sanitizer builds
# (which reserve terabytes of address space up front), at most 2 GiB of
# address space, so an input that makes rl allocate gigabytes fails the
# test instead of the machine. Its peak RSS (KiB) is left in $TMP/rss.
RL_SANITIZED=$(grep -c -m1 __asan_init "$RL" 2>/dev/null || true)
bounded() {
    (
        [ "$RL_SANITIZED" != 0 ] || ulimit -v 2097152
        exec /usr/bin/time -q -f %M -o "$TMP/rss" timeout 30 "$@"
    )
}
# expect_bounded_error CODE TEXT CMD...: expect_error under bounded, with a
# peak RSS below 512 MiB.
expect_bounded_error() {
    local code=$1 text=$2; shift 2
    expect_error "$code" "$text" bounded "$@"
    [ "$(tail -n1 "$TMP/rss")" -lt 524288 ] || fail "'$*' peaked at $(tail -n1 "$TMP/rss") KiB"
}

# available_algos: the renderers rl algos lists, less those it marks
# unavailable on this machine (a GL renderer without a GL context).
available_algos() {
    "$RL" algos | awk '/^[a-z0-9+-]+: / { name = $1; sub(":$", "", name); names[++n] = name }
                       /^  unavailable: / { gone[name] = 1 }
                       END { for (i = 1; i <= n; i++) if (!(names[i] in gone)) print names[i] }'
}

# xvfb CMD...: CMD under a fresh Xvfb server (xvfb-run -a). xvfb-run itself
# exits 5 when it cannot remove its temporary directory after CMD has run
# (seen once in a fresh-clone make check, under load); that is the
# wrapper's failure, not CMD's, so CMD then runs once more. Its output is
# held back until the run that counts, so a caller sees one run's output.
xvfb() {
    local out err rc
    out=$(mktemp) err=$(mktemp)
    xvfb-run -a -s "-screen 0 640x480x24" "$@" >"$out" 2>"$err"
    rc=$?
    if [ "$rc" -eq 5 ] && grep -q "problem while cleaning up temporary directory" "$err"; then
        echo "xvfb: xvfb-run failed to clean up after itself (exit 5): running once more" >&2
        xvfb-run -a -s "-screen 0 640x480x24" "$@" >"$out" 2>"$err"
        rc=$?
    fi
    cat "$out"
    cat "$err" >&2
    rm -f "$out" "$err"
    return "$rc"
}
