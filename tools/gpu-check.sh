#!/bin/sh
# tools/gpu-check.sh [BUILD] [OUT] — what to run on a machine with an OpenCL GPU.
#
# The test suite runs on PoCL (make test installs it); this script checks the same
# guarantees on whatever OpenCL GPU the machine has, and measures it:
#   1. the devices, as clpt lists them, and start-up: a cold kernel build (empty cache,
#      before anything else builds) and a warm one;
#   2. every kernel on the GPU against the scalar C twin, bit for bit, and the
#      whole-image tests with the GPU as their OpenCL device (CLPT_TEST_OPENCL=gpu,
#      tests/harness.h; test_kernels spends minutes in NVIDIA's compiler on its
#      traversal benchmark program, one CPU core's work, so it runs beside the steps
#      after start-up and its result is printed last);
#   3. whole images: GPU alone, scalar alone and both together give the same bits, for
#      every shipped scene and the two peer scenes (../shared beside the checkout), and
#      with each wave launch mode;
#   4. throughput: bench_render (every device, then scalar), the wave launch mode and
#      size on large renders, both trees with both launch modes per scene, and
#      --profile.
# Each step has its own time limit; everything is also written under OUT.
# Run from the repository root after `make` and `make test` (or make the build/tests/test_*
# programs named below and build/bench/bench_render). On a machine without clpt's
# packages, tools/gpu-bundle.sh packs the programs, their libraries and the shared
# files, and its run.sh sets up the OpenCL loader and runs this script.
set -u
# The tests run with the GPU as their OpenCL device, besides test_kernels (last); one
# line, which tools/gpu-bundle.sh reads to pack them.
image_tests="sampler render whitted envmap cubemap alpha curves mis gltf pbrt cli spawn bsdf media instance grid_media"
build=${1:-build}
out=${2:-gpu-check}
dev=${GPU_CHECK_DEVICE:-gpu}    # another device spec tries the script out without a GPU
mkdir -p "$out"
clpt=$build/clpt
cache=$(mktemp -d)
export CLPT_CACHE_DIR="$cache"
step() { echo; echo "== $*"; }
# GPU_CHECK_PARTS: the parts to run (default all): startup tests images bench waves trees
# profile kernels. With test_kernels beside the others, all but waves took 6 minutes of
# one call in the eighth check on an H200 (test_kernels 5.7, of which NVIDIA compiled
# for 3.3; start-up and tests 3.4; images, bench, trees and profile 1.1); waves adds 24
# renders of 1024x1024. The throughput steps share the CPU with NVIDIA's compiler then;
# GPU_CHECK_PARTS="bench waves trees profile" alone measures them quietly.
want() { case " ${GPU_CHECK_PARTS:-all} " in *" all "* | *" $1 "*) return 0 ;; esac; return 1; }
lim() { t=$1; shift; timeout "$t" "$@"; rc=$?; [ $rc -eq 124 ] && echo "(stopped after ${t}s)"; return $rc; }

step devices
lim 60 "$clpt" --list-devices

if want startup; then
step "start-up (16x16, 1 spp): cold, then warm"
for kind in cold warm; do
    s=$(date +%s%N)
    lim 120 "$clpt" scenes/cornell-box.scene --device "$dev" --width 16 --height 16 --spp 1 -q \
        --stats -o "$out/startup.pfm" | grep -i kernels
    echo "$kind: $(( ($(date +%s%N) - s) / 1000000 )) ms"
done
fi

if [ "$dev" = gpu ]; then export CLPT_TEST_OPENCL=gpu; else export CLPT_TEST_OPENCL=cpu; fi
kernels_pid=
if want kernels; then
    (lim 480 "$build/tests/test_kernels" >"$out/test_kernels.log" 2>&1; echo $? >"$out/test_kernels.rc") &
    kernels_pid=$!
fi
if want tests; then
step "tests with the GPU as their OpenCL device, against the scalar device"
for test in $image_tests; do
    [ -x "$build/tests/test_$test" ] || continue
    lim 240 "$build/tests/test_$test" >"$out/test_$test.log" 2>&1
    echo "test_$test: exit $?, $(grep -E 'passed, .* failed' "$out/test_$test.log" | tail -n 1)"
    grep -E 'FAIL' "$out/test_$test.log" | head -n 10
done
fi

if want images; then
step "whole images: gpu = scalar = gpu,scalar (same seed, bits of the PFM)"
same=0; differ=0
check() { # NAME SCENE ARGS...
    name=$1; scene=$2; shift 2
    [ -f "$scene" ] || { echo "skip $name: $scene is missing"; return; }
    for d in "$dev" scalar "$dev,scalar"; do
        f="$out/$name-$(echo "$d" | sed "s/^$dev/gpu/; s/,/+/").pfm"
        lim 90 "$clpt" "$scene" --device "$d" --seed 7 -q -o "$f" "$@" \
            || echo "$name on $d: exit $?"
    done
    a="$out/$name-gpu.pfm"
    if cmp -s "$a" "$out/$name-scalar.pfm" && cmp -s "$a" "$out/$name-gpu+scalar.pfm"; then
        echo "same   $name"; same=$((same + 1))
    else
        echo "DIFFER $name"; differ=$((differ + 1))
        command -v python3 >/dev/null && python3 - "$a" "$out/$name-scalar.pfm" <<'EOF'
import sys, struct
def pfm(p):
    b = open(p, 'rb').read()
    parts = b.split(b'\n', 3)
    w, h = map(int, parts[1].split()); return w, h, struct.unpack('<%df' % (w * h * 3), parts[3][:w * h * 12])
try:
    w, h, a = pfm(sys.argv[1]); _, _, b = pfm(sys.argv[2])
    d = [abs(x - y) for x, y in zip(a, b)]
    n = sum(1 for x in d if x > 0)
    print('    %d of %d values differ, largest difference %.3g, mean %.3g' % (n, len(d), max(d), sum(d) / len(d)))
except Exception as e:
    print('    cannot compare: %s' % e)
EOF
    fi
}
check cornell scenes/cornell-box.scene --width 256 --height 256 --spp 16
check weekend scenes/one-weekend.scene --width 400 --height 225 --spp 8
check mesh scenes/mesh.scene --width 256 --height 256 --spp 8
check envmap scenes/envmap.scene --width 240 --height 136 --spp 8
check materials scenes/materials.scene --width 240 --height 136 --spp 8
check classic scenes/classic/glass.txt --integrator path --spp 16
check mcguire ../shared/peers/cornell-mcguire.scene --width 256 --height 256 --spp 16
check dragon ../shared/peers/dragon.scene --width 256 --height 256 --spp 4
check cornell-counted scenes/cornell-box.scene --width 256 --height 256 --spp 16 --wave-launch counted
check cornell-megakernel scenes/cornell-box.scene --width 256 --height 256 --spp 16 --wave-launch megakernel
check weekend-megakernel scenes/one-weekend.scene --width 400 --height 225 --spp 8 --wave-launch megakernel
check fog scenes/fog.scene --width 192 --height 144 --spp 8
check fog-megakernel scenes/fog.scene --width 192 --height 144 --spp 8 --wave-launch megakernel
check fog-split scenes/fog.scene --width 192 --height 144 --spp 4 --split 3
check media-split tests/data/media/split.scene
check instances scenes/instances.scene --width 192 --height 144 --spp 8
check instances-megakernel scenes/instances.scene --width 192 --height 144 --spp 8 --wave-launch megakernel
check coated scenes/coated.pbrt --width 160 --height 120 --spp 8
check principled scenes/principled-extensions.scene --width 192 --height 144 --spp 8
check smoke scenes/smoke.scene --width 160 --height 120 --spp 8
check smoke-megakernel scenes/smoke.scene --width 160 --height 120 --spp 8 --wave-launch megakernel
check instanced-lamps scenes/instanced-lamps.scene --width 160 --height 120 --spp 8
check pbrt-instances scenes/pbrt-instances.pbrt --width 180 --height 90 --spp 8
check adaptive scenes/cornell-box.scene --width 128 --height 128 --spp 64 --noise-threshold 0.05
check adaptive-megakernel scenes/cornell-box.scene --width 128 --height 128 --spp 64 --noise-threshold 0.05 --wave-launch megakernel
echo "$same same, $differ differ"
fi

if want bench; then
step "throughput: bench_render (median of 3)"
lim 300 "$build/bench/bench_render" --reps 3 --json "$out/bench_render.json"
fi

if want waves; then
step "wave launches and sizes, taking turns (Msamples/s, the total line of --stats)"
for sc in ../shared/peers/cornell-mcguire.scene:256 ../shared/peers/dragon.scene:64 scenes/one-weekend.scene:64; do
    f=${sc%:*}; spp=${sc##*:}
    [ -f "$f" ] || continue
    for round in $(seq "${GPU_CHECK_ROUNDS:-2}"); do
        for wl in counted bounded; do
            for wp in 1048576 4194304; do
                r=$(lim 120 "$clpt" "$f" --device "$dev" --width 1024 --height 1024 --spp "$spp" --wave-paths $wp \
                    --wave-launch $wl --split 1 --stats -q -o "$out/waves.pfm" 2>&1 | grep '^total' | awk '{print $(NF-2)}')
                echo "$(basename "$f") 1024x1024 ${spp} spp, round $round, --wave-launch $wl --wave-paths $wp: $r Msamples/s"
            done
        done
    done
done
fi

# On an H200 the kd-tree walk was 10-35% faster than the 8-wide BVH on the small Cornell
# box and the BVH 30% faster on the dragon, and the megakernel slower on four of five
# renders (bench/RESULTS.md, "Third GPU check"): the numbers a per-device tree would be
# chosen by. Both trees give the same hits, so the images do not depend on it.
if want trees; then
step "trees and launch modes, taking turns (Msamples/s)"
for sc in scenes/cornell-box.scene:512:16 ../shared/peers/cornell-mcguire.scene:1024:64 scenes/mesh.scene:512:16 \
          ../shared/peers/dragon.scene:1024:16 scenes/one-weekend.scene:1024:16; do
    f=${sc%%:*}; rest=${sc#*:}; size=${rest%%:*}; spp=${rest#*:}
    [ -f "$f" ] || continue
    for wl in bounded megakernel; do
        for acc in bvh kdtree; do
            r=$(lim 120 "$clpt" "$f" --device "$dev" --width "$size" --height "$size" --spp "$spp" --accel $acc \
                --wave-launch $wl --split 1 --stats -q -o "$out/trees.pfm" 2>&1 | grep '^total' | awk '{print $(NF-2)}')
            echo "$(basename "$f") ${size}x${size} ${spp} spp, --wave-launch $wl --accel $acc: $r Msamples/s"
        done
    done
done
fi

# --split auto (the default since 2026-11-29) chooses the same split on every device, and
# a split render runs the megakernel on a GPU (slower than bounded launches on four of
# five renders of the third check). The images are the same bits as the CPU's, so their
# error is the CPU's: the GPU's time at the chosen split against its time at split 1,
# times the error ratio measured on the CPU (bench/RESULTS.md, "First-hit splitting
# chosen per render"), says whether auto pays on the GPU. The launch and tree steps above
# pin --split 1 to compare launches.
if want split; then
step "split auto against --split 1 (render seconds, the total line of --stats)"
for sc in ../shared/peers/cornell-mcguire.scene:64 ../shared/peers/dragon.scene:16 scenes/mesh.scene:16; do
    f=${sc%:*}; spp=${sc##*:}
    [ -f "$f" ] || continue
    for split in auto 1; do
        r=$(lim 120 "$clpt" "$f" --device "$dev" --width 1024 --height 1024 --spp "$spp" --split $split --stats -q \
            -o "$out/split.pfm" 2>&1 | grep -E '^split|^total' | awk '/^split/ {c=$2; sub(",", "", c)} /^total/ {t=$3} END {print c, t}')
        echo "$(basename "$f") 1024x1024 ${spp} spp, --split $split: split and seconds $r"
    done
done
fi

if want profile; then
step "profile: where the GPU's time goes"
profile() { # SCENE [ARGS...]
    [ -f "$1" ] || return
    echo "-- $*"
    lim 120 "$clpt" "$@" --device "$dev" --profile -q -o "$out/profile.pfm" 2>&1 | tail -n 25
}
profile scenes/cornell-box.scene
profile ../shared/peers/cornell-mcguire.scene
profile ../shared/peers/dragon.scene
# a load large enough to keep the GPU busy between host round trips
profile ../shared/peers/cornell-mcguire.scene --width 1024 --height 1024 --spp 256
profile ../shared/peers/dragon.scene --width 1024 --height 1024 --spp 64
fi
if [ -n "$kernels_pid" ]; then
step "kernels: GPU against scalar, bit for bit (run beside the steps above)"
wait "$kernels_pid"
summary=$(grep -E 'passed, .* failed' "$out/test_kernels.log" | tail -n 1)
echo "test_kernels: exit $(cat "$out/test_kernels.rc"), $summary"
grep -E 'FAIL|built in' "$out/test_kernels.log" | head -n 20
fi
unset CLPT_TEST_OPENCL
rm -rf "$cache"
