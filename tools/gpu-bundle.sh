#!/bin/sh
# tools/gpu-bundle.sh [BUILD] [DIR] — packs what tools/gpu-check.sh needs on a GPU machine
# that has an OpenCL driver but none of clpt's packages (the lent H100/H200 machines:
# Ubuntu, no package registry, and only the repository travels).
#
# DIR (default .gpu, which .git/info/exclude should list) receives:
#   build/   clpt, the test programs gpu-check.sh runs and bench_render, stripped;
#   lib/     every shared library they load except the C library's own (the ocl-icd
#            loader among them), as this machine has them;
#   shared/  the parts of ../shared the checks read (the dragon gzipped);
#   run.sh   to run there, from the repository root: it points the loader at the
#            driver's libnvidia-opencl.so.1 (and at this machine's ICDs, so that it can
#            be tried here), puts build/ and ../shared in place and runs gpu-check.sh
#            with its arguments: sh DIR/run.sh OUT (GPU_CHECK_PARTS picks parts).
# It makes the programs it packs first, then packs DIR as DIR.tar.xz (about 25 MB; DIR
# itself grew to 59 MB, over the 64 MiB that one call carries with the working tree) and
# removes DIR: there, `tar -xJf .gpu.tar.xz && sh .gpu/run.sh OUT`. Unpack it in every
# call: the machine keeps ignored build outputs between calls, not the unpacked DIR.
set -eu
build=${1:-build}
dir=${2:-.gpu}
tests="kernels $(sed -n 's/^image_tests="\(.*\)"$/\1/p' tools/gpu-check.sh)"
[ "$tests" != "kernels " ] || { echo "gpu-bundle: no image_tests line in tools/gpu-check.sh" >&2; exit 1; }
rm -rf "$dir"
mkdir -p "$dir/build/tests" "$dir/build/bench" "$dir/lib" "$dir/shared/models/dragon" "$dir/shared/envmaps"
progs="$build/clpt $build/bench/bench_render"
for t in $tests; do progs="$progs $build/tests/test_$t"; done
# shellcheck disable=SC2086
make -s BUILD="$build" $progs
for p in $progs; do
    cp "$p" "$dir/build/${p#"$build"/}"
done
strip "$dir/build/clpt" "$dir/build/bench/"* "$dir/build/tests/"*
# shellcheck disable=SC2086
ldd $progs | awk '/=> \// { print $3 }' | sort -u |
    grep -vE '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s)\.so' |
    while read -r lib; do cp -L "$lib" "$dir/lib/"; done
s=../shared
cp -r "$s/peers" "$dir/shared/"
cp -r "$s/models/cornell-box" "$s/models/gltf" "$s/models/bunny" "$dir/shared/models/"  # bunny: scenes/instances.scene
gzip -1 -c "$s/models/dragon/dragon_vrip.ply" >"$dir/shared/models/dragon/dragon_vrip.ply.gz"
for m in courtyard.hdr courtyard-dwab.exr forest.hdr forest-dwab.exr; do cp "$s/envmaps/$m" "$dir/shared/envmaps/"; done
chmod -R u+w "$dir"
cat >"$dir/run.sh" <<'EOF'
#!/bin/sh
# Made by tools/gpu-bundle.sh: sh .gpu/run.sh OUT, from the repository root.
set -u
here=$(cd "$(dirname "$0")" && pwd)
icd=$(mktemp -d)
nv=$(ls /usr/local/nvidia/lib64/libnvidia-opencl.so.1 /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 2>/dev/null | head -n 1)
[ -n "$nv" ] || nv=$(find / \( -path /proc -o -path /sys \) -prune -o -name 'libnvidia-opencl.so.1' -print 2>/dev/null | head -n 1)
[ -n "$nv" ] && echo "$nv" >"$icd/nvidia.icd"
for f in /etc/OpenCL/vendors/*.icd; do [ -f "$f" ] && cp "$f" "$icd/"; done
echo "OpenCL drivers: $(cat "$icd"/*.icd 2>/dev/null | tr '\n' ' ')"
mkdir -p build && cp -r "$here/build/." build/
[ -e ../shared ] || ln -s "$here/shared" ../shared
[ -f "$here/shared/models/dragon/dragon_vrip.ply" ] || gunzip -k "$here/shared/models/dragon/dragon_vrip.ply.gz"
export OCL_ICD_VENDORS="$icd" LD_LIBRARY_PATH="$here/lib:/usr/local/nvidia/lib64:${LD_LIBRARY_PATH:-}"
sh tools/gpu-check.sh build "${1:-gpu-check}"
EOF
tar -cJf "$dir.tar.xz" "$dir"
rm -rf "$dir"
echo "gpu-bundle: $(du -sh "$dir.tar.xz" | cut -f1) in $dir.tar.xz; run there: tar -xJf $dir.tar.xz && sh $dir/run.sh OUT"
