#!/usr/bin/env bash
# Safety net for refactors that must not change behaviour (issue 17): runs a grasp-sim binary on
# every bundled scenario and compares what it writes with a baseline, byte for byte.
#
#   scripts/structure_diff.sh record DIR [BIN]   write the outputs of BIN into DIR (the baseline)
#   scripts/structure_diff.sh check DIR [BIN]    write them again into a temp dir and diff with DIR
#   scripts/structure_diff.sh rev REV            build REV (in a temporary worktree), record its
#                                                outputs, build this tree, check against them
#
# BIN defaults to target/release/grasp-sim of this tree, built first (`cargo build --release`).
# Both runs read the same inputs: this tree's scenarios/*.toml and scenarios/hands/*.toml.
# Compared: the JSON lines (keys sorted; the wall-clock timings `wall_ms` and `timings_ms`
# removed, and the check's "N ms" in report.html), the exit status and stderr, and every file of --export-mjcf, --export-urdf and
# --report (SVG figures, glTF scenes, report.html). A second pass adds --payload and
# --candidates 3 (about 40 s); QUICK=1 skips it.
# Exit status: 0 identical, 1 different (the diff is printed), 2 usage or build error.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

usage() {
    sed -n '4,8p' "$0" >&2
    exit 2
}

build_here() {
    cargo build --release --quiet >&2 || exit 2
    echo "$root/target/release/grasp-sim"
}

# Strips wall-clock timings wherever they appear, sorts keys: one JSON object per line.
normalise() {
    jq -S -c 'walk(if type == "object" then with_entries(select(.key | test("^(wall_ms|timings_ms)$") | not)) else . end)'
}

# run BIN OUT: every scenario through BIN, outputs under OUT.
run_all() {
    local bin=$1 out=$2
    rm -rf "$out"
    mkdir -p "$out"
    local scenarios=(scenarios/*.toml scenarios/hands/*.toml)
    local status=0
    "$bin" --json --export-mjcf "$out/mjcf" --export-urdf "$out/urdf" --report "$out/report" \
        "${scenarios[@]}" >"$out/run.raw" 2>"$out/run.stderr" || status=$?
    echo "$status" >"$out/run.status"
    normalise <"$out/run.raw" >"$out/run.jsonl"
    rm "$out/run.raw"
    sed -i "s#$out#OUT#g" "$out/run.stderr"
    # report.html prints the physics check's wall-clock time ("980 steps, 442 ms").
    find "$out/report" -name report.html -exec sed -i -E 's/steps, [0-9]+ ms/steps, N ms/' {} +
    if [ "${QUICK:-0}" != 1 ]; then
        status=0
        "$bin" --json --payload --candidates 3 "${scenarios[@]}" \
            >"$out/payload.raw" 2>"$out/payload.stderr" || status=$?
        echo "$status" >"$out/payload.status"
        normalise <"$out/payload.raw" >"$out/payload.jsonl"
        rm "$out/payload.raw"
    fi
}

check() {
    local base=$1 bin=$2
    local new
    new=$(mktemp -d)
    run_all "$bin" "$new/out"
    local skip=()
    [ "${QUICK:-0}" = 1 ] && skip=(-x 'payload.*')
    if diff -r "${skip[@]}" "$base" "$new/out"; then
        echo "structure_diff: identical ($(find "$base" -type f | wc -l) files)"
        rm -rf "$new"
    else
        echo "structure_diff: DIFFERENT (new outputs kept in $new/out)"
        exit 1
    fi
}

case "${1:-}" in
record)
    [ $# -ge 2 ] || usage
    run_all "${3:-$(build_here)}" "$2"
    echo "structure_diff: baseline in $2 ($(find "$2" -type f | wc -l) files)"
    ;;
check)
    [ $# -ge 2 ] || usage
    check "$2" "${3:-$(build_here)}"
    ;;
rev)
    [ $# -ge 2 ] || usage
    tmp=$(mktemp -d)
    git worktree add --detach "$tmp/src" "$2" >&2
    # Share this tree's target dir so the dependencies are not built again.
    (cd "$tmp/src" && CARGO_TARGET_DIR="$root/target" cargo build --release --quiet) >&2 || exit 2
    cp "$root/target/release/grasp-sim" "$tmp/grasp-sim-base"
    git worktree remove --force "$tmp/src"
    run_all "$tmp/grasp-sim-base" "$tmp/base"
    check "$tmp/base" "$(build_here)"
    rm -rf "$tmp"
    ;;
*) usage ;;
esac
