# bench/view_common.sh: what bench/view.sh and bench/view_glshare.sh share,
# sourced by both (not run by itself): the Xvfb command they start rl view
# under, the selection of runs by a regular expression, and the record that
# gathers every run's --stats-out (each script's own fields already added)
# into one JSON file. Both scripts cd to the repository root first.

# rl view under a virtual X server with a screen larger than the largest
# window (1280x720 plus decorations).
VIEW_XVFB=(xvfb-run -a -s "-screen 0 1920x1080x24")

# view_selected RUN REGEX: true where REGEX is empty or RUN (a line of the
# script's RUNS) matches it.
view_selected() {
    [[ -z "$2" || "$1" =~ $2 ]]
}

# view_write_record OUT TMP WHO BENCHMARK NOTE: writes OUT from TMP/run<i>.json
# in the order of i, with BENCHMARK, the machine ($RL_MACHINE) and NOTE, and
# says so on stdout as WHO.
view_write_record() {
    python3 - "$@" <<'PY'
import glob, json, os, sys
out, tmp, who, benchmark, note = sys.argv[1:6]
runs = [json.load(open(f)) for f in sorted(glob.glob(tmp + "/run*.json"), key=lambda f: int(f.split("run")[-1][:-5]))]
json.dump({"benchmark": benchmark,
           "machine": os.environ.get("RL_MACHINE", "(set RL_MACHINE to name it)"),
           "note": note,
           "runs": runs}, open(out, "w"), indent=1)
print(who + ": wrote", out, "(%d runs)" % len(runs), flush=True)
PY
}
