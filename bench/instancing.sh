#!/bin/sh
# bench/instancing.sh — instancing at scale (docs/instancing.md), two benches:
#
#   bench/instancing.sh [N=100] [DEVICE=cpu]
#     an instanced scene against the same scene as copies: load + build, render time
#     and peak memory of N bunnies placed by instances, and by N mesh blocks with the
#     same transforms (the copies), both through the BVH on the chosen device, and how
#     alike their images are (the per-sample speed goal: instanced / copies <= 1.3).
#   bench/instancing.sh dragons [N=10000] [DEVICE=cpu] [WxH=160x90] [SPP=4]
#     issue 42's memory goal: N instances of the 871,414-triangle Stanford dragon
#     (8.7 billion instanced triangles at N = 10,000) on a 100-wide grid, each under
#     its own rotation, scale and material; load, build, Msamples/s, peak RSS
#     (/usr/bin/time -v) and the bytes per instance of the devices' records and top
#     level (clpt --stats). The image is kept in /tmp (its path is printed).
#
# From the repository root, after make; reads ../shared/models. Results: RESULTS.md.
set -e
if [ "$1" = dragons ]; then
    N=${2:-10000}
    DEV=${3:-cpu}
    SIZE=${4:-160x90}
    SPP=${5:-4}
    OUT=$(mktemp -d /tmp/clpt-dragons-XXXXXX)
    MODEL="$(pwd)/../shared/models/dragon/dragon_vrip.ply"
    [ -f "$MODEL" ] || { echo "no $MODEL" >&2; exit 1; }
    # a seeded grid: the dragon is about 0.2 wide, scaled 8..12 it is about 2
    awk -v n="$N" -v model="$MODEL" 'BEGIN {
        srand(42); side = int(sqrt(n)); if (side * side < n) side++
        print "image { width 160 height 90 spp 4 depth 4 }"
        print "camera { from -3 3.2 -3  at " side * 0.4 " 0 " side * 0.5 "  up 0 1 0  fov 45 }"
        print "background { horizon 0.85 0.9 1.0  zenith 0.25 0.4 0.85 }"
        print "light { type directional direction -0.4 -1 0.3 intensity 2.6 2.4 2.1 }"
        print "material ground { type diffuse albedo 0.45 0.42 0.38 }"
        print "material jade { type diffuse albedo 0.3 0.6 0.4 }"
        print "material clay { type diffuse albedo 0.7 0.35 0.22 }"
        print "material gold { type conductor metal Au roughness 0.25 }"
        print "plane { point 0 0 0 normal 0 1 0 material ground }"
        print "object dragon { mesh { file \"" model "\" material jade } }"
        split("jade clay gold", mats, " ")
        for (i = 0; i < n; i++) {
            x = (i % side) * 2.2 + rand() * 0.4; z = int(i / side) * 2.2 + rand() * 0.4
            s = 8 + rand() * 4
            printf "instance dragon { scale %.2f ry %.1f translate %.3f %.3f %.3f material %s }\n",
                   s, rand() * 360, x, -0.053 * s, z, mats[1 + int(rand() * 3)]
        }
    }' > "$OUT/dragons.scene"
    W=${SIZE%x*}
    H=${SIZE#*x}
    /usr/bin/time -v build/clpt "$OUT/dragons.scene" --device "$DEV" --width "$W" --height "$H" --spp "$SPP" \
        --stats -o "$OUT/dragons.png" > "$OUT/log" 2>&1 || { cat "$OUT/log"; exit 1; }
    grep -E "^clpt: rendered|^scene:|^BVH:|^instances:|^levels:|kernels|^total " "$OUT/log"
    awk '/^BVH: built in/ { build = $4 }
         /kernels (compiled|loaded)/ { for (i = 1; i <= NF; i++) { if ($i == "in") k = $(i + 1); if ($i == "upload") u = $(i + 1) } }
         /^clpt: rendered/ { for (i = 1; i <= NF; i++) { if ($i == "in") r = $(i + 1); if ($i == "total):") t = substr($(i - 2), 2) } }
         /Maximum resident set size/ { rss = $6 }
         END { printf "dragons: total %.2f s = load %.2f + build %.2f + kernels %.2f + upload %.2f + render %.2f s; peak RSS %.0f MiB\n",
                      t, t - build - k - u - r, build, k, u, r, rss / 1024 }' "$OUT/log"
    echo "image: $OUT/dragons.png"
    exit 0
fi
N=${1:-100}
DEV=${2:-cpu}
OUT=$(mktemp -d /tmp/clpt-inst-bench-XXXXXX)
head=$(sed -n '/^image/,/^}/p' scenes/instances.scene | sed '/^object/,$d')
insts=$(grep '^instance bunny' scenes/instances.scene | head -n "$N")
MODEL="$(pwd)/../shared/models/bunny/bun_zipper.ply"
{
    echo "$head"
    echo "object bunny { mesh { file \"$MODEL\" material cream } }"
    echo "$insts"
} > "$OUT/instanced.scene"
{
    echo "$head"
    echo "$insts" | sed "s|^instance bunny {|mesh { file \"$MODEL\"|"
} > "$OUT/copies.scene"
for kind in instanced copies; do
    /usr/bin/time -f "$kind: %e s wall, peak RSS %M KiB" build/clpt "$OUT/$kind.scene" --device "$DEV" \
        --width 320 --height 180 --spp 16 --stats -q -o "$OUT/$kind.pfm" 2>&1 |
        grep -E "^(scene|BVH|instances|levels|total):|^total |peak RSS" || true
done
python3 - "$OUT/instanced.pfm" "$OUT/copies.pfm" <<'PY'
import struct, sys
def rd(p):
    f = open(p, 'rb'); f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
    return struct.unpack(('<' if s < 0 else '>') + '%df' % (w * h * 3), f.read(w * h * 12))
a, b = rd(sys.argv[1]), rd(sys.argv[2])
print("image means: instanced %.6f, copies %.6f; %d of %d channels identical" %
      (sum(a) / len(a), sum(b) / len(b), sum(x == y for x, y in zip(a, b)), len(a)))
PY
rm -rf "$OUT"
