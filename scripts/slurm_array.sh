#!/usr/bin/env bash
# grasp-sim on a Slurm job array: each array task runs one shard of the inputs, resumably; a
# merge step puts the shards together in input order and checks that every input is there
# exactly once.
#
#   jid=$(sbatch --parsable --array=0-15 scripts/slurm_array.sh task OUT_DIR [BATCH FLAGS] INPUTS...)
#   sbatch --dependency=afterany:$jid scripts/slurm_array.sh merge OUT_DIR [BATCH FLAGS] INPUTS...
#
# Give both steps the same flags and inputs (they decide each object's input hash). Task K of
# N (K counted from the array's first index, N the array's size) runs
#
#   grasp-sim batch --shard K/N --resume --out OUT_DIR/shards/shard-K-of-N.jsonl --jobs CPUS ...
#
# so a task that is preempted and requeued (--requeue) or run again by hand continues its
# shard. The merge step writes OUT_DIR/results.jsonl and OUT_DIR/results.csv and prints the
# dataset summary. `afterany`, not `afterok`: a task whose shard holds an object's error line
# exits 2 (Slurm says FAILED) although its shard is complete; the merge's check is what tells
# a finished run from an unfinished one, and it fails (exit 2, nothing written) until every
# shard is complete. The array must be a plain range (`0-15`, `1-64`, `0-30:2`; a `%4`
# throttle is fine), not a list.
#
# The binary: $GRASP_SIM, else grasp-sim on the PATH; GRASP_SIM_COMMAND=label labels grasps
# (`grasp-sim label`, its flags in place of the batch flags) instead of running a batch.
# Other settings are ordinary sbatch options: change them here or on the sbatch command line.
#
#SBATCH --job-name=grasp-sim
#SBATCH --array=0-15
#SBATCH --cpus-per-task=4
#SBATCH --time=04:00:00
#SBATCH --requeue
#SBATCH --output=grasp-sim-%A_%a.out

set -euo pipefail

die() {
    echo "slurm_array.sh: error: $*" >&2
    exit 2
}

[ $# -ge 3 ] || die "usage: slurm_array.sh task|merge OUT_DIR [BATCH FLAGS] INPUTS..."
mode=$1
out=$2
shift 2
grasp_sim=${GRASP_SIM:-grasp-sim}
# The command each task runs: batch (one line per object) or label (one line per grasp).
command=${GRASP_SIM_COMMAND:-batch}
case $command in batch | label) ;; *) die "GRASP_SIM_COMMAND is batch or label, not \`$command\`" ;; esac

case $mode in
task)
    id=${SLURM_ARRAY_TASK_ID:-}
    [ -n "$id" ] || die "not a Slurm array task (SLURM_ARRAY_TASK_ID is not set); submit with sbatch --array"
    min=${SLURM_ARRAY_TASK_MIN:?}
    max=${SLURM_ARRAY_TASK_MAX:?}
    step=${SLURM_ARRAY_TASK_STEP:-1}
    n=$(((max - min) / step + 1))
    if [ -n "${SLURM_ARRAY_TASK_COUNT:-}" ] && [ "$SLURM_ARRAY_TASK_COUNT" -ne "$n" ]; then
        die "the array ($SLURM_ARRAY_TASK_COUNT tasks between $min and $max) is not a plain range: use --array=A-B or A-B:S"
    fi
    k=$(((id - min) / step + 1))
    shard=$(printf '%s/shards/shard-%05d-of-%05d.jsonl' "$out" "$k" "$n")
    mkdir -p "$out/shards"
    echo "slurm_array.sh: job ${SLURM_ARRAY_JOB_ID:-?} task $id: shard $k/$n -> $shard" >&2
    exec "$grasp_sim" "$command" --shard "$k/$n" --resume --out "$shard" \
        --jobs "${SLURM_CPUS_PER_TASK:-1}" "$@"
    ;;
merge)
    [ -d "$out/shards" ] || die "$out/shards: no such folder (did the array run?)"
    # A failed check writes nothing: no results from an earlier merge may stand in for them.
    rm -f "$out/results.jsonl" "$out/results.csv"
    status=0
    "$grasp_sim" "$command" --merge "$out/shards" --out "$out/results.jsonl" "$@" || status=$?
    if [ "$command" = batch ] && [ -f "$out/results.jsonl" ]; then
        "$grasp_sim" summarize "$out/results.jsonl" --csv "$out/results.csv"
    fi
    exit "$status"
    ;;
*)
    die "the first argument is task or merge, not \`$mode\`"
    ;;
esac
