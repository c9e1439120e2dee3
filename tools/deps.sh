#!/bin/sh
# deps.sh [--check] PROFILE... — makes sure the Debian packages a task needs are installed.
#
# With --check nothing is installed, even as root: a missing package is reported with
# the apt-get line and the script fails (what make targets use; run.sh and .ci/run
# install).
#
# Profiles: base (build and run clpt, run the tests), viewer-test (the viewer's test
# under a virtual display; run.sh test and .ci/run install it), install-test (man and
# zsh for the install test; likewise), deb (make deb), sanitize (make test-asan),
# valgrind (make test-valgrind), fuzz (make fuzz), embree (the traversal benchmark),
# peers (the renderers make bench-peers and make xcheck compare with: Debian's blender
# for Cycles and libllvm19 for Mitsuba's llvm_ad_rgb variant, then Mitsuba 3 itself with
# pip, as no Debian package has it), oidn (Intel Open Image Denoise for --denoise:
# no Debian package; tools/oidn_fetch.sh puts its official binaries into build/oidn).
# Neither peers nor oidn is needed by make test.
# Missing packages are installed when run as root (apt-get); otherwise the exact
# command to run is printed and the script fails, so nothing half-works.
set -eu

pkgs_for() {
    case "$1" in
        base) echo "make gcc g++ clang-15 libc6-dev pocl-opencl-icd ocl-icd-opencl-dev opencl-c-headers libstb-dev libpng-dev openmpi-bin libopenmpi-dev pkg-config libsdl2-dev libopenexr-dev libcjson-dev zlib1g-dev" ;;
        # the viewer's test (tests/test_viewer.c): a virtual display and input to send it
        viewer-test) echo "xvfb xdotool" ;;
        # the install test (tests/test_install.c): man renders the page, zsh loads the completion
        install-test) echo "man-db zsh" ;;
        # make deb: dpkg-deb (dpkg) and dpkg-shlibdeps (dpkg-dev)
        deb) echo "dpkg dpkg-dev" ;;
        sanitize) echo "clang libclang-rt-14-dev" ;;
        valgrind) echo "valgrind" ;;
        fuzz) echo "clang libclang-rt-14-dev" ;;
        embree) echo "libembree-dev" ;;
        # make bench-peers and make xcheck: Cycles, and Mitsuba 3's LLVM variant (Mitsuba
        # itself: pip, after the packages; install_mitsuba below)
        peers) echo "blender python3-numpy libllvm19" ;;
        # not a package: fetched after the packages (fetch_oidn below)
        oidn) echo "" ;;
        *) echo "deps.sh: unknown profile '$1'" >&2; exit 2 ;;
    esac
}

check_only=0
if [ "${1:-}" = "--check" ]; then check_only=1; shift; fi
[ $# -gt 0 ] || set -- base
wanted=""
oidn=0
peers=0
for profile in "$@"; do
    wanted="$wanted $(pkgs_for "$profile")"
    [ "$profile" = oidn ] && oidn=1
    [ "$profile" = peers ] && peers=1
done

# Mitsuba 3 (the version bench/peers.py and tools/xcheck were matched with) into the
# python3 that runs them, with pip's ordinary client; a Debian python3 that refuses pip
# (PEP 668) gets the package into the user's site instead of a half-done system change.
MITSUBA_VERSION=3.9.1
install_mitsuba() {
    [ "$peers" -eq 1 ] || return 0
    python3 -c "import mitsuba" >/dev/null 2>&1 && return 0
    if [ "$check_only" -eq 1 ]; then
        echo "Mitsuba 3 (for make bench-peers and make xcheck) is missing; install it with: sh tools/deps.sh peers" >&2
        return 1
    fi
    if ! python3 -m pip --version >/dev/null 2>&1; then
        echo "deps.sh: Mitsuba 3 needs pip (Debian: sudo apt-get install -y python3-pip)" >&2
        return 1
    fi
    python3 -m pip install --quiet "mitsuba==$MITSUBA_VERSION" numpy >&2 ||
        python3 -m pip install --quiet --user --break-system-packages "mitsuba==$MITSUBA_VERSION" numpy >&2
}

# what is fetched or installed after the Debian packages
after_packages() {
    fetch_oidn
    install_mitsuba
}

# Open Image Denoise into build/oidn (tools/oidn_fetch.sh says why when it cannot). It is
# optional: run.sh goes on without it, and --denoise then names this command.
fetch_oidn() {
    [ "$oidn" -eq 1 ] || return 0
    if [ "$check_only" -eq 1 ]; then
        [ -f "${BUILD:-build}/oidn/lib/libOpenImageDenoise.so.2" ] && return 0
        echo "Open Image Denoise (for --denoise) is missing; fetch it with: sh tools/deps.sh oidn" >&2
        return 1
    fi
    sh "$(dirname "$0")/oidn_fetch.sh"
}

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "deps.sh: this is not a Debian-based system; install the equivalents of:$wanted" >&2
    after_packages
    exit
fi

missing=""
for p in $wanted; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        case " $missing " in *" $p "*) ;; *) missing="$missing $p" ;; esac
    fi
done
if [ -z "$missing" ]; then
    after_packages
    exit
fi

if [ "$check_only" -eq 0 ] && [ "$(id -u)" -eq 0 ]; then
    echo "deps.sh: installing missing packages:$missing" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2
    # shellcheck disable=SC2086
    apt-get install -y -qq --no-install-recommends $missing >&2
    after_packages
else
    echo "clpt needs these Debian packages, which are missing:$missing" >&2
    echo "Install them with:" >&2
    if [ "$(id -u)" -eq 0 ]; then
        echo "    apt-get install -y$missing" >&2
    else
        echo "    sudo apt-get install -y$missing" >&2
    fi
    exit 1
fi
