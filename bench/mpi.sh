#!/bin/sh
# mpi.sh [BUILD] — the MPI driver's numbers (docs/distributed.md, bench/RESULTS.md):
#
#  1. efficiency: one process with 2 scalar threads against mpirun -np 1 and -np 2 with
#     one thread per rank, on the Cornell box (the same image every time: checked). On a
#     machine shared with other jobs the wall time says little (2 processes get a bigger
#     share of the cores than 1 process with 2 threads); the CPU time of the whole job
#     (every rank, start-up included) is the fairer measure of what MPI costs;
#  2. the coordinator: a tiny image (8x8) with --batch 1, so that almost all of the
#     time is rank 0 handing out batches and taking films back, with 8 and 16 ranks
#     oversubscribed on this machine's cores. Each batch is 3 messages (BATCH, RESULT,
#     FILM); messages/s = 3 * batches / render seconds, overhead = render seconds *
#     workers / batches (what one batch costs its rank besides rendering).
#
# The render time is the one clpt prints ("in X s"), which leaves out start-up (MPI_Init,
# the scene, the devices). Each configuration runs REPS times (default 3); the median is
# printed.
set -eu
build=${1:-build}
reps=${REPS:-3}
prog="$build/clpt"
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$PWD/$build/pocl-cache}"
export CLPT_CACHE_DIR="${CLPT_CACHE_DIR:-$PWD/$build/kernel-cache}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mpirun="mpirun --oversubscribe --allow-run-as-root --mca btl self,vader"

# once CMD...: "RENDER_SECONDS CPU_SECONDS": the render time clpt reports, and the CPU
# time (user + system) of the whole command, every rank included
once() {
    /usr/bin/time -f '%U %S' -o "$tmp/cpu" "$@" > "$tmp/out" 2>&1 || { cat "$tmp/out" >&2; exit 1; }
    r=$(sed -n 's/.* spp in \([0-9.]*\) s .*/\1/p' "$tmp/out" | tail -n 1)
    c=$(awk '{ print $1 + $2 }' "$tmp/cpu")
    echo "$r $c"
}

median() {
    sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}

# run NAME CMD...: REPS times; prints NAME and the medians, and leaves them in $tmp/t
# (render seconds) and $tmp/c (CPU seconds)
run() {
    name=$1
    shift
    for i in $(seq "$reps"); do once "$@"; done > "$tmp/runs"
    cut -d' ' -f1 "$tmp/runs" | median > "$tmp/t"
    cut -d' ' -f2 "$tmp/runs" | median > "$tmp/c"
    printf '%-36s render %7.3f s   CPU %7.2f s\n' "$name" "$(cat "$tmp/t")" "$(cat "$tmp/c")"
}

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'); $(mpirun --version | head -n 1)"
echo
echo "== efficiency (scenes/cornell-box.scene 160x120, 64 spp, scalar device)"
scene="scenes/cornell-box.scene --width 160 --height 120 --spp 64 --device scalar --seed 1"
run "1 process, 1 thread" "$prog" $scene --threads 1 -o "$tmp/a.pfm"
t1=$(cat "$tmp/t") c1=$(cat "$tmp/c")
run "1 process, 2 threads" "$prog" $scene --threads 2 -o "$tmp/b.pfm"
t2=$(cat "$tmp/t") c2=$(cat "$tmp/c")
run "mpirun -np 1, 1 thread" $mpirun -np 1 "$prog" $scene --threads 1 -o "$tmp/c.pfm"
run "mpirun -np 2, 1 thread per rank" $mpirun -np 2 "$prog" $scene --threads 1 -o "$tmp/d.pfm"
tm=$(cat "$tmp/t") cm=$(cat "$tmp/c")
for f in b c d; do cmp -s "$tmp/a.pfm" "$tmp/$f.pfm" || { echo "mpi.sh: $f.pfm differs from a.pfm" >&2; exit 1; }; done
echo "images: identical"
awk -v a="$t1" -v b="$t2" -v m="$tm" -v ca="$c1" -v cb="$c2" -v cm="$cm" 'BEGIN {
    printf "wall: speed-up over 1 thread: 2 threads %.2fx, 2 ranks %.2fx (2 threads / 2 ranks: %.0f%%)\n", a / b, a / m, 100 * m / b
    printf "CPU: 2 ranks use %.0f%% of the CPU time of 1 process with 2 threads (efficiency %.0f%%)\n", 100 * cm / cb, 100 * cb / cm }'
echo
echo "== coordinator (8x8 pixels, 2000 spp, --batch 1: 2000 batches)"
tiny="scenes/cornell-box.scene --width 8 --height 8 --spp 2000 --batch 1 --device scalar --threads 1 --seed 1"
run "1 process" "$prog" $tiny -o "$tmp/t1.pfm"
base=$(cat "$tmp/t")
for n in 8 16; do
    run "mpirun -np $n" $mpirun -np "$n" "$prog" $tiny -o "$tmp/t$n.pfm"
    cmp -s "$tmp/t1.pfm" "$tmp/t$n.pfm" || { echo "mpi.sh: -np $n image differs" >&2; exit 1; }
    awk -v s="$(cat "$tmp/t")" -v n="$n" -v b="$base" 'BEGIN {
        printf "  -np %d: %.0f messages/s, %.0f batches/s; %.2f ms per batch per worker rank (1 process: %.3f ms)\n",
               n, 3 * 2000 / s, 2000 / s, 1000 * s * (n - 1) / 2000, 1000 * b / 2000 }'
done
