#!/bin/sh
# check_layers.sh — host/ is layered; a file may include headers of its own layer and of
# the layers below it, never above. The layers, lowest first:
#
#   base    errors, files, hashing, limits, timing, progress (needs nothing of clpt)
#   scene   the scene containers: materials, shapes, transforms, the mesh sink, camera
#   io      everything that reads or writes a file: the one loader and its parsers,
#           images in and out
#   accel   the kd-tree over the scene's triangles
#   device  OpenCL and the scalar device behind one interface
#   render  scheduler, film, checkpoints, passes
#   dist    one image from many processes: merging --sample-range parts, the MPI
#           driver (docs/distributed.md)
#   viewer  the interactive window (docs/viewer.md): its camera, its renderer, SDL
#   app     host/*.c: options and main
#   api     the library's public interface (include/clpt/clpt.h, docs/api.md): a render
#           through it reads its settings with the program's option table, so it sits
#           on top of everything, the app layer's own files included
#
# Headers of kernels/ (shared structs, math) may be included from any layer. Prints
# every include that points up and exits 1 if there is one; run by `make test`.
set -eu
cd "$(dirname "$0")/.."
layers="base scene io accel device render dist viewer app api"

rank() {
    i=0
    for l in $layers; do
        [ "$l" = "$1" ] && { echo $i; return; }
        i=$((i + 1))
    done
    echo -1
}

bad=0
files=0
for f in host/*.[ch] host/*/*.[ch]; do
    [ -f "$f" ] || continue
    files=$((files + 1))
    dir=$(dirname "$f")
    case "$dir" in host) own=app ;; *) own=${dir#host/} ;; esac
    own_rank=$(rank "$own")
    if [ "$own_rank" -lt 0 ]; then
        echo "check_layers: $f is in host/$own, which is not a layer ($layers)" >&2
        bad=1
        continue
    fi
    # shellcheck disable=SC2013
    for inc in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f"); do
        # the kernels (compiled as C by the scalar device, their types and maths shared
        # with the host) sit below every layer
        if [ -f "kernels/$inc" ]; then continue; fi
        case "$inc" in
            */*) layer=${inc%%/*} ;;
            *)
                # a bare name is a header of the app layer (host/), which only the app
                # and api layers may include
                if [ -f "host/$inc" ] && [ "$own_rank" -ge "$(rank app)" ]; then continue; fi
                echo "check_layers: $f includes \"$inc\": name the layer (\"LAYER/$inc\")" >&2
                bad=1
                continue ;;
        esac
        r=$(rank "$layer")
        if [ "$r" -lt 0 ] || [ ! -f "host/$inc" ]; then
            echo "check_layers: $f includes \"$inc\", which is not a header of host/" >&2
            bad=1
        elif [ "$r" -gt "$own_rank" ]; then
            echo "check_layers: $f ($own) includes \"$inc\" ($layer): an include points up" >&2
            bad=1
        fi
    done
done
# host/ and kernels/ are both on the include path (-Ihost -Ikernels): a header at the same
# path in both would make an include mean whichever comes first.
for k in $(cd kernels && find . -name '*.h' | sed 's#^\./##'); do
    if [ -f "host/$k" ]; then
        echo "check_layers: host/$k and kernels/$k share a path: rename one" >&2
        bad=1
    fi
done
[ "$bad" -eq 0 ] && echo "check_layers: $files files in host/, every include points down or sideways"
exit "$bad"
