#!/usr/bin/env bash
# The steps of forkbench's CI gate, shared by github-actions.yml and gitlab-ci.yml:
#   steps.sh build   build forkbench
#   steps.sh batch   the candidate's batch, with the committed baseline's seed and counts
#   steps.sh gate    the gate against the committed baseline (exit 3: a row dropped)
# Settings come from the environment (defaults: the main job on the embedded scenarios,
# gated against the baseline forkbench commits):
#   FORKBENCH_BASELINE   the committed baseline (forkbench baseline DIR --out FILE)
#   FORKBENCH_SCENARIOS  scenario files, space-separated (empty: the embedded defaults)
#   FORKBENCH_TRIALS     trials per case, as the baseline's batch ran
#   FORKBENCH_ARGS       further batch arguments (--components ci/components.toml --tracker mine)
#   FORKBENCH_AS         CANDIDATE=SHIPPED, to gate a component of yours as the baseline's
#   FORKBENCH_OUT        where the batch, the report, the recordings and the JUnit go
set -euo pipefail
: "${FORKBENCH_BASELINE:=scenarios/baselines/default.json}"
: "${FORKBENCH_SCENARIOS:=}"
: "${FORKBENCH_TRIALS:=20}"
: "${FORKBENCH_ARGS:=}"
: "${FORKBENCH_AS:=}"
: "${FORKBENCH_OUT:=forkbench-ci}"
forkbench="${CARGO_TARGET_DIR:-target}/release/forkbench"

case "${1:-}" in
  build)
    cargo build --release --locked -p forkbench-cli
    ;;
  batch)
    # Failed trials are recorded (MCAP; rerun .rrd too with --features rerun) under
    # $FORKBENCH_OUT/batch/recordings/.
    # shellcheck disable=SC2086 # the scenario list and the arguments are word lists
    "$forkbench" batch $FORKBENCH_SCENARIOS --trials "$FORKBENCH_TRIALS" $FORKBENCH_ARGS \
      --out "$FORKBENCH_OUT/batch" --report --junit "$FORKBENCH_OUT/batch.xml"
    ;;
  gate)
    as=()
    if [ -n "$FORKBENCH_AS" ]; then as=(--as "$FORKBENCH_AS"); fi
    "$forkbench" regress --baseline "$FORKBENCH_BASELINE" "$FORKBENCH_OUT/batch" "${as[@]}" \
      --junit "$FORKBENCH_OUT/regress.xml"
    ;;
  *)
    echo "usage: $0 build|batch|gate" >&2
    exit 2
    ;;
esac
