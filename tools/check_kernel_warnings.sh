#!/bin/sh
# check_kernel_warnings.sh — the kernels compile without a warning for every feature
# set: an OpenCL driver compiles kernels/entry.cl for the scene's features
# (-D CLPT_FEATURES, kernels/types.h) on a user's first render, and a warning there is
# printed to the user's terminal by the driver's compiler ("1 warning generated."), where
# clpt cannot catch it. Compiling out a feature turns its KF_HAS() into a constant, which
# is where such warnings come from (a constant operand of || or &&, code that cannot be
# reached), so each feature is checked both taken away from all of them and added alone
# to a plain diffuse megakernel, with and without a fixed work-group size. clang checks
# the syntax only, with its own OpenCL C header; it is the compiler PoCL runs. Run by
# `make test`.
set -eu
cd "$(dirname "$0")/.."
cc=$(command -v clang-15 || command -v clang || true)
if [ -z "$cc" ]; then
    echo "check_kernel_warnings: no clang-15 or clang (Debian: apt-get install clang-15)" >&2
    exit 1
fi
base=$((0x80000 | 0x200000 | 0x800))   # KF_PATH_MEGAKERNEL | KF_BVH | diffuse
masks=""
i=0
while [ $i -lt 32 ]; do
    bit=$((1 << i))
    masks="$masks $(( 0xffffffff & ~bit )) $(( base | bit ))"
    i=$((i + 1))
done
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for m in $masks; do
    for size in "" "-D CLPT_LOCAL_SIZE=64"; do
        printf '%s\n' "$(printf '0x%xu' "$m") $size"
    done
done | xargs -P 2 -I '{}' sh -c '
    set -- {}
    if ! msg=$("$0" -x cl -cl-std=CL1.2 -Xclang -finclude-default-header -fsyntax-only -I kernels \
               -D CLPT_FEATURES="$1" ${2:+"$2"} ${3:+"$3"} kernels/entry.cl 2>&1) || [ -n "$msg" ]; then
        printf "CLPT_FEATURES=%s %s %s:\n%s\n" "$1" "${2:-}" "${3:-}" "$msg"
    fi' "$cc" >"$out"
if [ -s "$out" ]; then
    echo "check_kernel_warnings: the kernels do not compile cleanly for every feature set:" >&2
    head -40 "$out" >&2
    exit 1
fi
echo "check_kernel_warnings: kernels/entry.cl compiles without a warning for 64 feature sets, with and" \
     "without a work-group size ($(basename "$cc"))"
