#!/bin/sh
# viewer.sh [BUILD] [DEVICE] — the viewer's responsiveness and overhead (docs/viewer.md),
# on the Cornell box at 512 x 512, under a virtual display (Xvfb, xdotool: sh
# tools/deps.sh viewer-test). Not part of `make bench` (it needs those tools).
#
# Starts `clpt --interactive --stats` on DEVICE (default: the default choice), waits
# 8 s, then presses W five times 2 s apart and lets the last view converge to 16 spp
# (the title says "(done)"; at most 3 minutes); Esc. Prints the viewer's own measurements (input rounds per second,
# frames drawn, camera change to first frame drawn, Msamples/s of the last view) and,
# for comparison, a command-line render of the same scene and spp on the same device.
set -eu
build=${1:-build}
device=${2:-}
root=$(cd "$(dirname "$0")/.." && pwd)
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$root/$build/pocl-cache}"
export CLPT_CACHE_DIR="${CLPT_CACHE_DIR:-$root/$build/kernel-cache}"
work=$(mktemp -d)
exec 3>"$work/displayfd"
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 2>/dev/null &
xvfb=$!
trap 'kill $viewer 2>/dev/null || true; kill $xvfb 2>/dev/null || true; rm -rf "$work"' EXIT
viewer=
for _ in $(seq 100); do [ -s "$work/displayfd" ] && break; sleep 0.1; done
export DISPLAY=":$(head -n 1 "$work/displayfd")"
set -- "$root/scenes/cornell-box.scene" --spp 16
[ -n "$device" ] && set -- "$@" --device "$device"
(cd "$work" && exec "$root/$build/clpt" --interactive --stats "$@" >"$work/out" 2>"$work/err") &
viewer=$!
for _ in $(seq 600); do grep -q "clpt: viewer:" "$work/err" 2>/dev/null && break; sleep 0.1; done
win=$(timeout 10 xdotool search --sync --name '^clpt' | head -n 1)
xdotool mousemove --window "$win" 256 256
sleep 8
for _ in 1 2 3 4 5; do xdotool key w; sleep 2; done
for _ in $(seq 900); do xdotool getwindowname "$win" | grep -q '(done)' && break; sleep 0.2; done
xdotool key Escape
wait $viewer || true
viewer=
cat "$work/err" "$work/out"
echo "command line, same scene and spp:"
"$root/$build/clpt" "$@" -o "$work/cli.png" 2>&1 | tail -n 1
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
