#!/bin/sh
# The thorough property run: every property test of ktree-verify with PROPTEST_CASES cases (default 5000;
# the quickcheck properties take the same count), one test binary at a time, timed, recorded in
# results/verification.md. Usage, from anywhere in the project:
#     verify/thorough.sh            # 5000 cases per property
#     PROPTEST_CASES=10000 verify/thorough.sh
# The tests run in cargo's test profile (optimised: opt-level 1, dependencies at 3).
set -eu
cd "$(dirname "$0")/.."
cases="${PROPTEST_CASES:-5000}"
export PROPTEST_CASES="$cases"
out=results/verification.md
tmp="$out.tmp.$$"
log=$(mktemp)
trap 'rm -f "$tmp" "$log"' EXIT

# Build once, then run the test binaries themselves (from the package folder, as cargo does).
built=$(cargo test -p ktree-verify --tests --no-run 2>&1) || { echo "$built" >&2; exit 1; }
root=$(pwd)
binary_of() {
    path=$(echo "$built" | sed -n "s|^ *Executable tests/$1\.rs (\(.*\))\$|\1|p")
    case "$path" in /*) echo "$path" ;; *) echo "$root/$path" ;; esac
}

rows=""
total_tests=0
total_props=0
total_time=0
start_all=$(date +%s)
for file in verify/tests/*.rs; do
    name=$(basename "$file" .rs)
    binary=$(binary_of "$name")
    tests=$(cd verify && "$binary" --list 2>/dev/null | grep -c ': test$' || true)
    # Plain tests start at column 0; the properties are inside proptest! blocks (indented), or are the
    # quickcheck(...) calls.
    plain=$(grep -c '^#\[test\]' "$file" || true)
    qc=$(grep -c '\.quickcheck(' "$file" || true)
    if [ "$qc" -gt 0 ]; then props=$qc; else props=$((tests - plain)); fi
    t0=$(date +%s)
    if ! (cd verify && "$binary" -q) >"$log" 2>&1; then
        cat "$log"
        echo "thorough run: $name failed" >&2
        exit 1
    fi
    secs=$(($(date +%s) - t0))
    rows="$rows| \`$name\` | $tests | $props | $secs |
"
    total_tests=$((total_tests + tests))
    total_props=$((total_props + props))
    echo "$name: $tests tests, $props properties, ${secs} s" >&2
done
total_time=$(($(date +%s) - start_all))

{
    echo "# Verification: the thorough property run"
    echo
    echo "Written by \`verify/thorough.sh\` (\`PROPTEST_CASES=$cases\`): every test binary of \`ktree-verify\`, each"
    echo "property run with $cases random cases (cases rejected by \`prop_assume!\` are not counted), against"
    echo "the reference builders (naive insertion, the dense array, brute force) and, at the largest level"
    echo "of each K (\`max_level\`), against references computed on boxes. All passed."
    echo
    echo "Machine: $(nproc) cores, $(rustc --version | cut -d' ' -f1-2); time is wall time of the test binary"
    echo "(its tests run in parallel), compilation excluded."
    echo
    echo "| test binary | tests | properties ($cases cases each) | time (s) |"
    echo "|---|---:|---:|---:|"
    printf "%s" "$rows"
    echo "| **total** | $total_tests | $total_props | $total_time |"
} >"$tmp"
mv "$tmp" "$out"
echo "wrote $out" >&2
