#!/bin/sh
# run.sh — the two commands of the README, usable on a fresh Debian 12 machine:
#
#   ./run.sh render   install what is missing, build, render scenes/cornell-box.scene
#                     to cornell-box.png
#   ./run.sh test     install what is missing, build, run the test suite
#
# Packages are installed when run as root; otherwise the exact apt-get command is
# printed and nothing else happens (see tools/deps.sh). Open Image Denoise (--denoise)
# is fetched into build/oidn too, when it can be: nothing else needs it.
set -eu
cd "$(dirname "$0")"
what=${1:-render}
case "$what" in
    render|test) ;;
    *) echo "usage: ./run.sh render|test" >&2; exit 2 ;;
esac
# the test suite also runs the viewer under a virtual display (tests/test_viewer.c) and
# checks the installed man page and zsh completion (tests/test_install.c)
if [ "$what" = test ]; then sh tools/deps.sh base viewer-test install-test; else sh tools/deps.sh base; fi
# --denoise's library (not a Debian package; optional: clpt works without it)
sh tools/deps.sh oidn || echo "run.sh: going on without Open Image Denoise (--denoise will not work)" >&2
jobs=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 2)
exec make -j"$jobs" "$what"
