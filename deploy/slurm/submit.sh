#!/bin/bash
# Submits a sharded forkbench batch as a Slurm job array plus a dependent merge (and
# regress) job. Usage:
#   FORKBENCH_OUT=/shared/run1 deploy/slurm/submit.sh SHARDS [forkbench batch arguments…]
# Optional: FORKBENCH (path to the binary), FORKBENCH_BASELINE (a baseline to gate on),
# SBATCH_EXTRA (more sbatch options, e.g. "--partition=cpu --time=01:00:00").
# Prints the array's and the merge's job ids.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
shards="${1:?usage: submit.sh SHARDS [batch args…]}"
shift
export FORKBENCH_SHARDS="$shards"
# shellcheck disable=SC2086
array=$(sbatch --parsable --export=ALL ${SBATCH_EXTRA:-} --array=0-$((shards - 1)) \
  "$here/forkbench-array.sbatch" "$@")
# shellcheck disable=SC2086
merge=$(sbatch --parsable --export=ALL ${SBATCH_EXTRA:-} --dependency=afterok:"$array" \
  "$here/merge.sbatch")
echo "$array $merge"
