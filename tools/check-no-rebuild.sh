#!/usr/bin/env bash
# A second `cargo build` compiles nothing, in a checkout with .git/packed-refs and in one
# without (cargo re-runs a build script on every build when it watches a missing file).
set -euo pipefail
cd "$(dirname "$0")/.."
git_dir=$(git rev-parse --git-dir)

second_build_is_fresh() {
  cargo build --release -q -p forkbench-cli
  local out
  out=$(cargo build --release -p forkbench-cli 2>&1)
  if grep -qE '^\s*(Compiling|Running)' <<<"$out"; then
    echo "spurious rebuild ($1):"
    echo "$out"
    exit 1
  fi
  echo "no rebuild ($1)"
}

state() { [ -f "$git_dir/packed-refs" ] && echo "with packed-refs" || echo "without packed-refs"; }

second_build_is_fresh "$(state)"
if [ -f "$git_dir/packed-refs" ]; then
  # Every ref loose, then no packed-refs file: what many checkouts look like.
  git for-each-ref --format='%(objectname) %(refname)' | while read -r obj ref; do
    mkdir -p "$git_dir/$(dirname "$ref")"
    echo "$obj" > "$git_dir/$ref"
  done
  rm "$git_dir/packed-refs"
else
  git pack-refs --all
fi
second_build_is_fresh "$(state)"
