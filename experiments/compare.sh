#!/usr/bin/env bash
# Times every case of the ops, display, build and solids reports against an earlier commit, side by side,
# and writes results/performance/compare.md.
#
#   experiments/compare.sh [COMMIT] [ROUNDS]     (defaults: eda9474, the last commit before the workspace
#                                                  split; 5 rounds)
#
# The earlier commit is checked out in a git worktree beside the project (../ktree-before-COMMIT: outside
# this workspace, so that cargo builds it as its own) and its perf example built there (a release build of
# that commit: minutes on a cold cache).
set -euo pipefail
cd "$(dirname "$0")/.."
commit=${1:-eda9474}
rounds=${2:-5}
before=../ktree-before-$commit
if [ ! -d "$before" ]; then
  git worktree add --detach "$before" "$commit"
fi
cargo build --release --example perf --manifest-path "$before/Cargo.toml"
cargo build --release --example perf
target/release/examples/perf compare "$before/target/release/examples/perf" "$commit" "$rounds"
