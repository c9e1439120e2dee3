#!/bin/sh
# oidn_fetch.sh [DIR] — puts Intel Open Image Denoise (the library --denoise loads at run
# time, docs/denoise.md) into DIR/lib (default: build/oidn/lib).
#
# OIDN is not packaged in Debian 12. Its official Linux binaries ship inside the
# `pyoidn` wheel on PyPI; the wheel is fetched with pip's ordinary client (no install:
# `pip download`), checked against the SHA-256 pinned below, and only the core library,
# its CPU and CUDA devices and TBB are unpacked. Nothing is linked against them: clpt
# opens them with dlopen when --denoise asks, so a machine without them builds and
# renders as before. Run by `sh tools/deps.sh oidn` (and ./run.sh).
set -eu
cd "$(dirname "$0")/.."
dir=${1:-${BUILD:-build}/oidn}
version=2.5.1
wheel=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
sha256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e

if [ -f "$dir/lib/libOpenImageDenoise.so.2" ] && [ -f "$dir/lib/libOpenImageDenoise_device_cpu.so.$version" ]; then
    exit 0
fi
if [ "$(uname -s)-$(uname -m)" != "Linux-x86_64" ]; then
    echo "oidn_fetch.sh: Open Image Denoise's wheel on PyPI is built for Linux x86_64 only;" \
         "install OIDN $version from https://www.openimagedenoise.org/ for --denoise" >&2
    exit 1
fi
if ! python3 -m pip --version >/dev/null 2>&1; then
    echo "oidn_fetch.sh: fetching Open Image Denoise needs pip (Debian: sudo apt-get install -y python3-pip)" >&2
    exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
echo "oidn_fetch.sh: fetching Open Image Denoise $version (the pyoidn wheel, about 90 MB) into $dir" >&2
if ! python3 -m pip download --quiet --no-deps --only-binary=:all: --dest "$tmp" "pyoidn==$version.0" >&2; then
    echo "oidn_fetch.sh: could not download pyoidn==$version.0 from PyPI (see pip's message above)" >&2
    exit 1
fi
if [ ! -f "$tmp/$wheel" ] || [ "$(sha256sum "$tmp/$wheel" | cut -d' ' -f1)" != "$sha256" ]; then
    echo "oidn_fetch.sh: the downloaded wheel is not $wheel with SHA-256 $sha256; refusing it" >&2
    exit 1
fi
# Only what the CPU and CUDA devices need (the wheel also holds SYCL and HIP devices,
# tens of MB more, that would need Intel's and AMD's runtimes as well).
python3 - "$tmp/$wheel" "$tmp/x" "$version" <<'PY'
import sys, zipfile
wheel, out, v = sys.argv[1:]
want = ["libOpenImageDenoise.so.%s" % v, "libOpenImageDenoise_core.so.%s" % v,
        "libOpenImageDenoise_device_cpu.so.%s" % v, "libOpenImageDenoise_device_cuda.so.%s" % v,
        "libtbb.so.12"]
with zipfile.ZipFile(wheel) as z:
    for name in want:
        z.extract("pyoidn/oidn/lib/" + name, out)
PY
mkdir -p "$dir.new/lib"
mv "$tmp/x/pyoidn/oidn/lib/"* "$dir.new/lib/"
# the names the libraries ask each other for (their RPATH is $ORIGIN/../lib)
ln -sf "libOpenImageDenoise.so.$version" "$dir.new/lib/libOpenImageDenoise.so.2"
printf 'Intel Open Image Denoise %s, from %s (SHA-256 %s), Apache License 2.0\n' "$version" "$wheel" "$sha256" \
    > "$dir.new/SOURCE"
rm -rf "$dir"
mv "$dir.new" "$dir"
echo "oidn_fetch.sh: Open Image Denoise $version is in $dir/lib" >&2
