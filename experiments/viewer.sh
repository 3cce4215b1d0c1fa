#!/usr/bin/env bash
# `ktree view` measured in headless Chromium: for spheres of about 10^6 and 10^8 nodes (L = 9 and 12) the
# time to write the page, its size and the writer's peak memory, and the page's load time (navigation start
# to the first frame drawn, as the page records it) and JavaScript heap; writes
# results/performance/viewer.md. Also takes the README's picture of the viewer, results/viewer/bunny.png
# (the Stanford bunny from data/meshes seen from above, coloured by depth, its controls showing).
# Usage: experiments/viewer.sh
# Needs chromium (Debian's package) and GNU time (/usr/bin/time).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p ktree-cli
bin=target/release/ktree
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome) || {
  echo "experiments/viewer.sh needs chromium" >&2
  exit 1
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking
  --disable-component-update --disable-sync --hide-scrollbars --use-angle=swiftshader --enable-unsafe-swiftshader
  --enable-precise-memory-info)
# The value of KEY in the page's status record, from a DOM dump.
status() { sed -e 's/^<pre id="ktree-status">//' -e 's/<\/pre>$//' "$1" | sed -n "s/^$2=\(.*\)$/\1/p" | head -n 1; }
load=$(cut -d' ' -f1-3 /proc/loadavg)
rows=()
for level in 9 12; do
  side=$((1 << level))
  tree="$work/ball$level.ktree"
  # The node count from the build's summary line ("… -> N nodes (…)").
  nodes=$("$bin" rays --solid ball --level "$level" --radius "$(((side - 1) / 2)).5" --out "$tree" |
    sed -n 's/.*-> \([0-9]*\) nodes.*/\1/p')
  page="$work/ball$level.html"
  /usr/bin/time -f "%e %M" -o "$work/time" "$bin" view "$tree" --out "$page" > "$work/view.out"
  read -r seconds kib < "$work/time"
  bytes=$(stat -c %s "$page")
  best=""
  for run in 1 2 3; do
    "$browser" "${flags[@]}" --user-data-dir="$work/profile$level-$run" --window-size=1024,768 --dump-dom \
      "file://$page#bare" 2> /dev/null > "$work/dom"
    errors=$(status "$work/dom" errors)
    [ "$errors" = 0 ] || { echo "the page of L = $level recorded errors" >&2; exit 1; }
    ms=$(status "$work/dom" first_frame_ms)
    if [ -z "$best" ] || awk "BEGIN { exit !($ms < $best) }"; then best=$ms; fi
  done
  boxes=$(status "$work/dom" boxes)
  coarse=$(status "$work/dom" coarse)
  heap=$(status "$work/dom" js_heap_bytes)
  rows+=("| $level | $nodes | $boxes | $coarse | $bytes | $seconds | $((kib / 1024)) | $best | $((heap / 1048576)) |")
done
out=results/performance/viewer.md
{
  echo "# The viewer: page size and load time"
  echo
  echo "Regenerate with \`experiments/viewer.sh\`. Object: the voxel-centre sphere (centre U/2, radius (U−1)/2) by"
  echo "\`ktree rays --solid ball\`; page by \`ktree view FILE --out PAGE\` with the default budget of 100000 boxes"
  echo "(the file read through its memory map). Writing: wall seconds and peak resident set of \`ktree view\` (GNU"
  echo "time), release build. Load: Debian's Chromium $("$browser" --version 2> /dev/null | awk '{print $2}'), headless,"
  echo "WebGL2 on SwiftShader (software: no GPU here), a 1024×768 window; the page records \`performance.now()\` when"
  echo "its first frame is drawn and finished (\`gl.finish\`) — from navigation start, so parsing the page, decoding"
  echo "the base64 boxes and drawing every box are in it; the best of 3 runs, each in a new browser profile. JS heap:"
  echo "\`performance.memory.usedJSHeapSize\` after the first frame. The boxes on the GPU take 32 bytes each."
  echo "Machine: $(nproc) cores shared with other work; load average at start: $load."
  echo
  echo "| L | nodes | boxes | coarse boxes | page bytes | write s | write peak MiB | load ms (first frame) | JS heap MiB |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
  printf '%s\n' "${rows[@]}"
} > "$out"
echo "wrote $out"
# The README's picture: the bunny with the viewer's controls.
mkdir -p results/viewer
"$bin" voxelize data/meshes/bunny_npm.obj --level 7 --fit --out "$work/bunny.ktree" > /dev/null
"$bin" view "$work/bunny.ktree" --camera top --out "$work/bunny.html" > /dev/null
"$browser" "${flags[@]}" --user-data-dir="$work/profile-shot" --window-size=640,480 \
  --screenshot="$work/bunny.png" "file://$work/bunny.html#colour=depth" 2> /dev/null > /dev/null
cp "$work/bunny.png" results/viewer/bunny.png
echo "wrote results/viewer/bunny.png"
