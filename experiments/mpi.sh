#!/usr/bin/env bash
# Builds of the voxel-centre sphere (centre U/2, radius (U-1)/2) over 1, 2 and 4 MPI ranks on this machine,
# writing results/performance/mpi.md: wall time, bytes sent to rank 0, peak memory per rank, and whether the
# file is byte-identical to the single-process one. Usage: experiments/mpi.sh [LEVELS...] (default 11 12 13).
# Needs OpenMPI (openmpi-bin, libopenmpi-dev) and libclang-dev; builds `ktree` with the cargo feature `mpi`.
set -euo pipefail
cd "$(dirname "$0")/.."
levels=("${@:-11 12 13}")
[ $# -gt 0 ] || levels=(11 12 13)
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
  echo "Every rank computes the rays and keeps its slab of columns; rank 0 receives the other ranks' trees"
  echo "(\`.ktree\` encoding) and joins them. 4 ranks on 2 cores are oversubscribed: they share the cores, so"
  echo "they show the cost of the partition and the join, not a speed-up. Each rank also uses all cores for its"
  echo "own cells (\`--threads\` default)."
  echo
  echo "| L | ranks | seconds | bytes sent to rank 0 | peak MiB per rank (rank 0 first) | same bytes as 1 process |"
  echo "|---|---:|---:|---:|---|---|"
} > "$work/report.md"
for L in "${levels[@]}"; do
  U=$((1 << L))
  args=(rays --solid ball --level "$L" --center "$((U / 2)),$((U / 2)),$((U / 2))" --radius "$(((U - 1) / 2)).5")
  for P in 1 2 4; do
    start=$(date +%s.%N)
    mpirun "${mca[@]}" -n "$P" "$bin" "${args[@]}" --out "$work/ball$P.ktree" > /dev/null 2> "$work/err"
    end=$(date +%s.%N)
    secs=$(echo "$end - $start" | bc)
    line=$(grep "ranks;" "$work/err" || true)
    moved=$(echo "$line" | sed -n 's/.*; \([0-9]*\) bytes sent.*/\1/p')
    peaks=$(echo "$line" | sed -n 's/.*(MiB): //p')
    same=yes
    cmp -s "$work/ball1.ktree" "$work/ball$P.ktree" || same=NO
    printf '| %s | %s | %.2f | %s | %s | %s |\n' "$L" "$P" "$secs" "${moved:-0}" "${peaks:-—}" "$same" >> "$work/report.md"
  done
done
cat "$work/report.md" docs/mpi.md > "$out.tmp" 2>/dev/null || cp "$work/report.md" "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
