#!/usr/bin/env bash
# A real Slurm job array on this machine: starts a one-node cluster (munge, slurmctld,
# slurmd), submits a 4-shard forkbench batch with deploy/slurm/submit.sh and its dependent
# merge job, and checks that the merged results equal one unsharded run with the same
# arguments (wall times aside). Then cancels one array task mid-run, resubmits that index,
# and checks that it resumed and that the merge still equals the unsharded run.
# Needs root (installs slurm-wlm and munge when missing). Usage:
#   tools/slurm-test.sh [path/to/forkbench]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="$(realpath "${1:-${CARGO_TARGET_DIR:-target}/release/forkbench}")"
[ -x "$bin" ] || { echo "no forkbench binary at $bin (cargo build --release -p forkbench-cli)"; exit 1; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q slurm-wlm munge >/dev/null
fi

work="$(mktemp -d /tmp/forkbench-slurm.XXXXXX)"
chmod 755 "$work"
host="$(hostname -s)"
cpus="$(nproc)"

# munge: a key and the daemon (as root, hence --force).
mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge
[ -s /etc/munge/munge.key ] || dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
chmod 400 /etc/munge/munge.key
pgrep -x munged >/dev/null || munged --force

# A one-node cluster with no cgroups (proctrack/linuxproc, task/none): works as root in a VM or container.
cat > "$work/slurm.conf" <<CONF
ClusterName=forkbench
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cleanup() {
  scancel --user=root >/dev/null 2>&1 || true
  [ -f "$work/slurmd.pid" ] && kill "$(cat "$work/slurmd.pid")" 2>/dev/null || true
  [ -f "$work/slurmctld.pid" ] && kill "$(cat "$work/slurmctld.pid")" 2>/dev/null || true
}
trap cleanup EXIT
slurmctld -c
slurmd
for _ in $(seq 60); do
  sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
  sleep 1
done
sinfo

args=(--trials 12 --seed 5 --record none)
wait_jobs() { # waits until none of the given job ids is queued or running
  for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] && return 0
    sleep 1
  done
  echo "jobs $1 did not finish"; squeue; exit 1
}

echo "== unsharded reference run"
"$bin" batch "${args[@]}" --out "$work/single" >/dev/null

echo "== 4-shard job array and dependent merge"
export FORKBENCH="$bin" FORKBENCH_OUT="$work/array"
ids=$(deploy/slurm/submit.sh 4 "${args[@]}")
echo "submitted array and merge: $ids"
wait_jobs "${ids// /,}"
sacct >/dev/null 2>&1 || true
python3 tools/compare_batches.py "$work/single" "$work/array/merged"

echo "== a cancelled array task, resubmitted, resumes"
export FORKBENCH_OUT="$work/requeue" FORKBENCH_SHARDS=4
# The pick scenarios only (embedded, by name): trials of a few milliseconds, so the
# cancelled task has written some of its share, and not all, when it is cancelled.
slow=(field-test rack-pick bspline-table2 spiral-table2 --trials 60 --seed 5 --record none)
"$bin" batch "${slow[@]}" --out "$work/single-slow" >/dev/null
array=$(sbatch --parsable --export=ALL --cpus-per-task=1 --array=0-3 deploy/slurm/forkbench-array.sbatch "${slow[@]}")
shard="$work/requeue/shard-2-of-4/trials.jsonl"
for _ in $(seq 2400); do
  [ -s "$shard" ] && [ "$(wc -l < "$shard")" -ge 20 ] && break
  sleep 0.05
done
scancel --signal=KILL "${array}_2"
wait_jobs "$array"
before=$(wc -l < "$shard")
expected=$(( $(wc -l < "$work/single-slow/trials.jsonl") / 4 ))
echo "shard 2 had $before of about $expected trials when cancelled"
[ "$before" -lt "$expected" ] || { echo "the task finished before it was cancelled: nothing tested"; exit 1; }
again=$(sbatch --parsable --export=ALL --cpus-per-task=1 --array=2 deploy/slurm/forkbench-array.sbatch "${slow[@]}")
wait_jobs "$again"
grep -h "resum\|trials" "forkbench-${again}_2.log" 2>/dev/null | tail -2 || true
merge=$(sbatch --parsable --export=ALL deploy/slurm/merge.sbatch)
wait_jobs "$merge"
python3 tools/compare_batches.py "$work/single-slow" "$work/requeue/merged"
rm -f forkbench-*.log forkbench-merge-*.log
echo "slurm test OK"
