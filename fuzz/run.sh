#!/usr/bin/env bash
# Runs every fuzz target (or the TARGETs given) for SECONDS each (default 60) or FUZZ_RUNS executions
# (default 10^7), whichever comes first, one after the other, and writes results/reliability.md:
# executions, time, crashes, coverage and peak memory per target. Each target's latest run is kept in
# fuzz/target/rows/, so a run of some targets updates their rows and keeps the others' (a target this
# machine has not run keeps its row from the committed results/reliability.md).
#
#   fuzz/run.sh [SECONDS] [TARGET...]
#
# Needs cargo-fuzz (`cargo install cargo-fuzz`) and a C++ compiler; the stable toolchain is enough with
# RUSTC_BOOTSTRAP=1, which this script sets (cargo-fuzz passes -Z flags to rustc). SANITIZER=address turns on
# AddressSanitizer (default none: the library forbids unsafe code, and a plain build runs several times faster).
# Each run starts from the committed seeds in fuzz/corpus/TARGET and keeps what it finds in
# fuzz/target/corpus/TARGET (not committed). A crash leaves its input in fuzz/artifacts/TARGET/.
# FUZZ_NO_REPORT=1 (the CI smoke run) leaves the record alone: neither results/reliability.md nor the kept rows
# are written. The exit status is 1 on any crash.
# FUZZ_REPORT_ONLY=1 runs nothing and writes results/reliability.md from the rows kept so far.
set -uo pipefail
cd "$(dirname "$0")"
seconds=${1:-60}
shift || true
runs=${FUZZ_RUNS:-10000000}
export RUSTC_BOOTSTRAP=1
sanitizer=${SANITIZER:-none}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cargo fuzz list)
fi
if [ "${FUZZ_REPORT_ONLY:-0}" = 1 ]; then
  targets=()
else
  cargo fuzz build -O -s "$sanitizer" || exit 1
fi
host=$(rustc -vV | sed -n "s/^host: //p")
logs=target/logs
rows_dir=target/rows
mkdir -p "$logs" "$rows_dir"
failed=0
for t in "${targets[@]}"; do
  mkdir -p "target/corpus/$t" "corpus/$t"
  start=$(date +%s)
  mkdir -p "artifacts/$t"
  # The binary cargo-fuzz built above, run directly (as `cargo fuzz run` would, without rebuilding).
  "target/$host/release/$t" -artifact_prefix="artifacts/$t/" \
    -max_total_time="$seconds" -runs="$runs" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 "target/corpus/$t" "corpus/$t" >"$logs/$t.log" 2>&1
  status=$?
  took=$(( $(date +%s) - start ))
  # -a: a log may hold raw bytes of inputs (dictionary entries), which would make grep call it binary.
  execs=$(grep -ao 'stat::number_of_executed_units: *[0-9]*' "$logs/$t.log" | grep -o '[0-9]*$' | tail -1)
  rss=$(grep -ao 'stat::peak_rss_mb: *[0-9]*' "$logs/$t.log" | grep -o '[0-9]*$' | tail -1)
  cov=$(grep -ao 'cov: [0-9]* ft: [0-9]*' "$logs/$t.log" | tail -1)
  if [ $status -eq 0 ]; then
    outcome="none"
  else
    failed=1
    # The kind of failure, and for a panic the source file's name (never a path of this machine).
    kind=$(grep -ao -m1 -E 'panicked at [^:]*|ERROR: libFuzzer: [a-z -]*|ERROR: AddressSanitizer: [a-z-]*' "$logs/$t.log" \
      | head -1 | sed -E 's#(panicked at ).*/#\1#')
    outcome="**${kind:-exit $status}** (see fuzz/artifacts/$t/)"
  fi
  echo "$t: ${execs:-?} executions in ${took} s, crashes: $outcome"
  if [ "${FUZZ_NO_REPORT:-0}" != 1 ]; then
    echo "| \`$t\` | ${execs:-?} | ${took} | $seconds s or $runs | $outcome | ${cov:-?} | ${rss:-?} |" >"$rows_dir/$t.md"
  fi
done
if [ "${FUZZ_NO_REPORT:-0}" = 1 ]; then
  exit $failed
fi
out=../results/reliability.md
# A target this machine has not run keeps the row the committed record has for it.
for t in $(cargo fuzz list); do
  if [ ! -f "$rows_dir/$t.md" ] && [ -f "$out" ]; then
    grep -m1 -F "| \`$t\` |" "$out" | grep -v "| not run |" >"$rows_dir/$t.md.tmp" && mv "$rows_dir/$t.md.tmp" "$rows_dir/$t.md"
    rm -f "$rows_dir/$t.md.tmp"
  fi
done
{
  echo "# Reliability: fuzzing"
  echo
  echo "Written by \`fuzz/run.sh SECONDS\` (libFuzzer through cargo-fuzz, sanitizer: $sanitizer, \`-rss_limit_mb=2048\`,"
  echo "\`-malloc_limit_mb=2048\`, \`-timeout=10\`): each target runs until SECONDS pass or \`FUZZ_RUNS\` executions"
  echo "are done (the budget column), starting from the committed seeds in \`fuzz/corpus/\` plus what earlier runs on"
  echo "this machine kept in \`fuzz/target/corpus/\`. Each row is its target's latest run. Coverage is libFuzzer's"
  echo "count of covered edges (\`cov\`) and features (\`ft\`) at the end of the run. The \`vdb\` target reads with"
  echo "the octree bounded to 2^16 nodes (\`io::read_vdb_within\`, as a reader of untrusted files would; the"
  echo "default bound, 2^20 + 2^5 nodes a byte, lets a 46 KB file make 2.5 million nodes, tens of milliseconds an"
  echo "execution in the fuzz build, and the inputs libFuzzer keeps gather there: 177 executions a second)."
  echo
  echo "| target | executions | seconds | budget | crashes in this run | coverage | peak RSS (MB) |"
  echo "|---|---:|---:|---|---|---|---:|"
  for t in $(cargo fuzz list); do
    if [ -f "$rows_dir/$t.md" ]; then
      cat "$rows_dir/$t.md"
    else
      echo "| \`$t\` | not run | | | | | |"
    fi
  done
  echo
  cat FINDINGS.md
} >"$out"
exit $failed
