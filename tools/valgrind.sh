#!/bin/sh
# valgrind.sh BUILD — small renders under valgrind memcheck (make test-valgrind):
# the scalar device (the kernels compiled as C, several threads), PoCL (the OpenCL host
# code, and the kernels PoCL compiles, running on clpt's buffers), an OBJ mesh, a PLY
# mesh on its own, a classic scene with image textures (the whitted integrator), an
# environment map from a DWAB EXR (written back as an EXR with AOV channels), an error
# path, and `clpt merge` of two parts (and one refused). Each must be clean: no invalid
# access, no use of uninitialised memory, no definite or indirect leak outside the
# OpenCL runtime (tools/sanitizers/valgrind.supp says what is suppressed there and why).
#
# Under valgrind the CPU reports fewer features (no AVX-512), so PoCL names the device
# differently and compiles the kernels again, inside valgrind: about two minutes the
# first time. The kernel caches live in BUILD/valgrind-cache, so later runs load them.
set -u
build=${1:-build}
prog="$build/clpt"
out="$build/valgrind"
mkdir -p "$out"
export CLPT_CACHE_DIR="$PWD/$build/valgrind-cache/clpt" POCL_CACHE_DIR="$PWD/$build/valgrind-cache/pocl"
mkdir -p "$CLPT_CACHE_DIR" "$POCL_CACHE_DIR"

failed=0
passed=0
# check NAME EXPECTED_EXIT ARGS...
check() {
    name=$1
    want=$2
    shift 2
    log="$out/$name.log"
    start=$(date +%s)
    valgrind --tool=memcheck --error-exitcode=99 --leak-check=full \
        --show-leak-kinds=definite,indirect --errors-for-leak-kinds=definite,indirect \
        --num-callers=40 --suppressions=tools/sanitizers/valgrind.supp \
        "$prog" "$@" >"$log" 2>&1
    rc=$?
    secs=$(( $(date +%s) - start ))
    errors=$(sed -n 's/.*ERROR SUMMARY: \([0-9]*\) errors.*/\1/p' "$log" | tail -n 1)
    if [ "$rc" -eq "$want" ] && [ "${errors:-1}" -eq 0 ]; then
        echo "ok    valgrind $name: exit $rc, 0 errors (${secs}s)"
        passed=$((passed + 1))
    else
        echo "FAIL  valgrind $name: exit $rc (expected $want), ${errors:-?} errors; log: $log"
        grep -E -A12 '^==[0-9]+== (Invalid|Conditional|Use of|Syscall|Mismatched|Source|[0-9,]+ .*(definitely|indirectly) lost)' "$log" |
            head -n 60 | sed 's/^/    /'
        failed=$((failed + 1))
    fi
}

small="--width 16 --height 12 --spp 2 -q"
check scalar 0 scenes/cornell-box.scene --device scalar --threads 2 $small -o "$out/scalar.png"
# scenes/mesh.scene draws one of the team's shared models (../shared/models)
if [ -f ../shared/models/cornell-box/CornellBox-Sphere.obj ]; then
    check mesh 0 scenes/mesh.scene --device scalar --threads 2 $small -o "$out/mesh.pfm"
else
    echo "skip  valgrind mesh: ../shared/models not beside this checkout"
fi
check ply-view 0 tests/data/models/bun_zipper_res4.ply --device scalar --threads 2 $small -o "$out/ply.png"
check classic-textured 0 scenes/classic/textured.txt --device scalar --threads 2 $small -o "$out/classic.png"
check pocl 0 scenes/cornell-box.scene --device cpu $small -o "$out/pocl.png"
# an environment map read from a DWAB EXR (OpenEXR), written back as EXR with AOV channels
check envmap-exr 0 tests/data/good/envmap-dwab.scene --device scalar --threads 2 $small -o "$out/envmap.exr" \
    --aov normal,depth,albedo
check bad-scene 3 tests/data/bad/not-a-number.scene --device scalar $small -o "$out/never.png"
# --sample-range parts (rendered here without valgrind), then clpt merge under it, and a
# merge refused for a gap (docs/distributed.md)
parts="scenes/cornell-box.scene --device scalar --threads 1 $small"
"$prog" $parts --sample-range 0:1 --checkpoint "$out/part1.ckpt" -o "$out/part1.pfm"
"$prog" $parts --sample-range 1:2 --checkpoint "$out/part2.ckpt" -o "$out/part2.pfm"
check merge 0 merge -q -o "$out/merged.pfm" "$out/part2.ckpt" "$out/part1.ckpt"
check merge-gap 3 merge -q -o "$out/never.pfm" "$out/part2.ckpt"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
