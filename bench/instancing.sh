#!/bin/sh
# bench/instancing.sh — an instanced scene against the same scene as copies
# (docs/instancing.md): load + build, render time and peak memory of N bunnies placed
# by instances, and by N mesh blocks with the same transforms (the copies), both through
# the BVH on the chosen device. Usage: bench/instancing.sh [N=100] [DEVICE=cpu]
# (from the repository root, after make; reads ../shared/models). Results: RESULTS.md.
set -e
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
