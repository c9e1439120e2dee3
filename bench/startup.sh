#!/bin/sh
# startup.sh [CLPT] [RUNS] — cold and warm start-up of clpt on its default device (PoCL):
# the Cornell box at 32x32, 1 spp, wall time of the whole process, median of RUNS (3).
# Cold: empty CLPT_CACHE_DIR and POCL_CACHE_DIR (the kernels are compiled, and PoCL
# compiles each kernel's work-group function again at its first launch). Warm: both
# caches filled by the run before. Also prints what --stats says the kernel build took,
# and whether the "compiling kernels" notice appeared (it must, cold only).
set -eu
clpt=${1:-build/clpt}
runs=${2:-3}
tmp=$(mktemp -d /tmp/clpt-startup-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
export CLPT_CACHE_DIR="$tmp/clpt-cache" POCL_CACHE_DIR="$tmp/pocl-cache"

one() {   # prints: wall seconds, kernel build seconds, notice yes/no
    start=$(date +%s.%N)
    "$clpt" scenes/cornell-box.scene --spp 1 --width 32 --height 32 -o "$tmp/out.png" --stats \
        >"$tmp/stdout" 2>"$tmp/stderr"
    end=$(date +%s.%N)
    build=$(sed -n 's/.*kernels .* in \([0-9.]*\) s,.*/\1/p' "$tmp/stdout")
    notice=no
    grep -q "compiling kernels for .*, cached for next time" "$tmp/stderr" && notice=yes
    echo "$(echo "$end - $start" | bc) $build $notice"
}

median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

: >"$tmp/cold"
: >"$tmp/warm"
for i in $(seq "$runs"); do
    rm -rf "$CLPT_CACHE_DIR" "$POCL_CACHE_DIR"
    mkdir -p "$CLPT_CACHE_DIR" "$POCL_CACHE_DIR"
    r=$(one); echo "cold run $i: wall $r" | sed 's/ \([0-9.]*\) \(yes\|no\)$/ s, kernels built in \1 s, notice: \2/'
    echo "$r" >>"$tmp/cold"
    r=$(one); echo "warm run $i: wall $r" | sed 's/ \([0-9.]*\) \(yes\|no\)$/ s, kernels loaded in \1 s, notice: \2/'
    echo "$r" >>"$tmp/warm"
done
echo "cold: median $(cut -d' ' -f1 "$tmp/cold" | median) s wall, kernel build $(cut -d' ' -f2 "$tmp/cold" | median) s"
echo "warm: median $(cut -d' ' -f1 "$tmp/warm" | median) s wall, kernel load $(cut -d' ' -f2 "$tmp/warm" | median) s"
