#!/usr/bin/env bash
# Builds of the voxel-centre sphere (centre U/2, radius (U-1)/2) over 1, 2 and 4 MPI ranks on this machine,
# writing results/performance/mpi.md: wall time, bytes sent to rank 0, peak memory (resident set) per rank,
# and whether the file is byte-identical to the single-process one; at every level with the default budget,
# and at the last level also with a small budget per rank (BUDGET, default 96M) and with 2 ranks of one
# thread each.
# Usage: experiments/mpi.sh [LEVELS...] (default 11 12 13).
# Needs OpenMPI (openmpi-bin, libopenmpi-dev), libclang-dev and GNU time (/usr/bin/time, for one process);
# builds `ktree` with the cargo feature `mpi`.
set -euo pipefail
cd "$(dirname "$0")/.."
levels=("$@")
[ $# -gt 0 ] || levels=(11 12 13)
budget=${BUDGET:-96M}
cargo build --release -p ktree-cli --features mpi
bin=target/release/ktree
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mca=(--oversubscribe --mca btl self,vader,tcp --mca btl_tcp_if_include lo --mca oob_tcp_if_include lo)
out=results/performance/mpi.md
{
  echo "# Builds over MPI ranks"
  echo
  echo "Regenerate with \`experiments/mpi.sh\` (OpenMPI from Debian, \`ktree\` built with the cargo feature \`mpi\`)."
  echo "Object: the voxel-centre sphere (centre U/2, radius (U−1)/2) by \`ktree rays --solid ball … --out F.ktree\`."
  echo "Machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo); load average at start: $(cut -d' ' -f1-3 /proc/loadavg)."
  echo "Each rank makes the rays of its own slabs only, stacks them out of core (spill files next to the output)"
  echo "and sends rank 0 its index and then its subtree levels, which rank 0 writes with its own into the one"
  echo "file. \"Bytes sent to rank 0\" counts both. Peak memory is each rank's peak resident set (VmHWM), MPI's"
  echo "own share included; one process is measured by GNU time. The budget is \`--max-memory\` per rank"
  echo "(default: half the machine's memory). This machine has $(nproc) cores: 2 ranks use one core each, but"
  echo "each rank also runs \`--threads\` = all cores for its slabs, so even 2 ranks oversubscribe the cores"
  echo "twice (the last row gives each of 2 ranks one thread); 4 ranks share the cores four times over. The"
  echo "times show what partition, streaming and the oversubscribed cores cost here, not the speed-up of ranks"
  echo "with cores of their own. Other work on the machine shows in the load average."
  echo
  echo "| L | ranks | threads per rank | budget per rank | seconds | bytes sent to rank 0 | peak MiB per rank (rank 0 first) | same bytes as 1 process |"
  echo "|---|---:|---|---|---:|---:|---|---|"
} > "$work/report.md"
run() { # L P BUDGET|default [THREADS]
  local L=$1 P=$2 B=$3 T=${4:-all} U=$((1 << $1))
  local args=(rays --solid ball --level "$L" --center "$((U / 2)),$((U / 2)),$((U / 2))" --radius "$(((U - 1) / 2)).5")
  [ "$B" = default ] || args+=(--max-memory "$B")
  [ "$T" = all ] || args+=(--threads "$T")
  local file="$work/ball-$P-$B.ktree" start end secs moved peaks same
  start=$(date +%s.%N)
  if [ "$P" = 1 ]; then
    /usr/bin/time -f "peak %M" "$bin" "${args[@]}" --out "$file" > /dev/null 2> "$work/err"
  else
    mpirun "${mca[@]}" -n "$P" "$bin" "${args[@]}" --out "$file" > /dev/null 2> "$work/err"
  fi
  end=$(date +%s.%N)
  secs=$(echo "$end - $start" | bc)
  if [ "$P" = 1 ]; then
    moved=0
    peaks=$(awk '/^peak / {printf "%.1f", $2 / 1024}' "$work/err")
    cp "$file" "$work/ball1.ktree"
  else
    line=$(grep "ranks;" "$work/err" || true)
    moved=$(echo "$line" | sed -n 's/.*; \([0-9]*\) bytes sent.*/\1/p')
    peaks=$(echo "$line" | sed -n 's/.*(MiB): //p')
  fi
  same=yes
  cmp -s "$work/ball1.ktree" "$file" || same=NO
  printf '| %s | %s | %s | %s | %.2f | %s | %s | %s |\n' "$L" "$P" "$T" "$B" "$secs" "${moved:-0}" "${peaks:-—}" "$same" >> "$work/report.md"
  rm -f "$file"
}
for L in "${levels[@]}"; do
  for P in 1 2 4; do run "$L" "$P" default; done
done
last=${levels[${#levels[@]}-1]}
for P in 1 2 4; do run "$last" "$P" "$budget"; done
run "$last" 2 default 1
{ cat "$work/report.md"; echo; cat docs/mpi.md; } > "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
