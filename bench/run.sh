#!/bin/sh
# Runs every benchmark program in BUILD/bench. Kernels are cached in the build folder so
# compile time is measured once and not in every run.
set -eu
build=${1:-build}
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$PWD/$build/pocl-cache}"
export CLPT_CACHE_DIR="${CLPT_CACHE_DIR:-$PWD/$build/kernel-cache}"
mkdir -p "$POCL_CACHE_DIR" "$CLPT_CACHE_DIR"
for b in "$build"/bench/bench_*; do
    [ -x "$b" ] || continue
    echo "== $(basename "$b")"
    "$b"
    echo
done
