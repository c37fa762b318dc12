#!/usr/bin/env bash
# A Slurm job array running `c3po certify --shard K/N` (issue 15,
# docs/camera_inputs.md). Each array task certifies one disjoint part; merge
# the parts afterwards (in task order) with `c3po merge`:
#
#   sbatch --array=1-16 scripts/slurm_certify.sh OBJECT.json OUT_DIR --bop SPLIT --obj-id 5 --detector svd
#   c3po merge -o OUT_DIR/poses.jsonl OUT_DIR/part_{1..16}.jsonl
#   c3po merge -o OUT_DIR/results.csv OUT_DIR/part_{1..16}.csv
#
# Any array range works (1-16 or 0-15): K counts from SLURM_ARRAY_TASK_MIN.
# Set C3PO to the c3po binary when it is not on PATH.
#SBATCH --job-name=c3po-certify
#SBATCH --cpus-per-task=2
#SBATCH --output=c3po-certify_%A_%a.log
set -euo pipefail
object=${1:?usage: slurm_certify.sh OBJECT.json OUT_DIR CERTIFY_OPTIONS...}
out=${2:?usage: slurm_certify.sh OBJECT.json OUT_DIR CERTIFY_OPTIONS...}
shift 2
c3po=${C3PO:-c3po}
count=${SLURM_ARRAY_TASK_COUNT:?not a Slurm array task (submit with sbatch --array=1-N)}
index=$(( SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-1} + 1 ))
mkdir -p "$out"
status=0
"$c3po" certify "$object" "$@" --shard "$index/$count" -o "$out/part_$index.jsonl" --bop-csv "$out/part_$index.csv" || status=$?
# certify exits 0 (all certified) or 1 (some not certified) on success, 2 on an error.
[ "$status" -le 1 ] || exit "$status"
