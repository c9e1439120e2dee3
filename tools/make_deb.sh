#!/bin/sh
# make_deb.sh BUILD VERSION — builds BUILD/clpt_VERSION_ARCH.deb with Debian's own tools
# (`make deb`; README, "Installing"): `make install PREFIX=/usr` into a staging folder,
# the package's Depends from dpkg-shlibdeps (the libraries the program and libclpt.so
# really link, at the versions this system has), then dpkg-deb. Binary-only: it packages
# what this checkout built, as `make install` installs it; not a Debian source package.
set -eu
build=$1
version=$2
arch=$(dpkg --print-architecture)
name=clpt_${version}_${arch}
stage=$build/deb/$name
rm -rf "$build/deb"
mkdir -p "$stage/DEBIAN"
# OIDN (build/oidn, a wheel's binaries) is left out: --denoise finds a packaged OIDN 2 on
# the system's library path (docs/denoise.md)
make --no-print-directory install PREFIX=/usr DESTDIR="$stage" BUILD="$build" INSTALL_OIDN=0 >/dev/null
# Debian's layout: man pages compressed, the licence in the package's doc folder
gzip -9n "$stage/usr/share/man/man1/clpt.1"
doc=$stage/usr/share/doc/clpt
mkdir -p "$doc"
{ printf 'clpt is licensed under the Apache License, Version 2.0:\n\n'; cat LICENSE
  printf '\n\nWhat clpt links or loads, and their licences (THIRD-PARTY.md):\n\n'; cat THIRD-PARTY.md; } > "$doc/copyright"
gzip -9nc CHANGELOG.md > "$doc/changelog.gz"

# dpkg-shlibdeps reads the package list from debian/control in the folder it runs in:
# a scratch one names the one binary package. The files are given as absolute paths.
scratch=$build/deb/shlibdeps
mkdir -p "$scratch/debian"
printf 'Source: clpt\n\nPackage: clpt\nArchitecture: any\n' > "$scratch/debian/control"
top=$(pwd)
files=""
for f in "$stage"/usr/bin/clpt "$stage"/usr/lib/libclpt.so.*; do
    [ -f "$f" ] && [ ! -L "$f" ] && files="$files $top/$f"
done
# shellcheck disable=SC2086
depends=$(cd "$scratch" && dpkg-shlibdeps -O -l"$top/$stage/usr/lib" $files 2>/dev/null |
          sed -n 's/^shlibs:Depends=//p')
[ -n "$depends" ] || { echo "make_deb.sh: dpkg-shlibdeps found no dependencies" >&2; exit 1; }

size=$(du -sk "$stage/usr" | cut -f1)
cat > "$stage/DEBIAN/control" <<CONTROL
Package: clpt
Version: $version
Architecture: $arch
Maintainer: clpt developers <clpt@localhost>
Installed-Size: $size
Depends: $depends
Recommends: pocl-opencl-icd
Section: graphics
Priority: optional
Description: portable OpenCL path tracer
 clpt renders scenes (its own format, pbrt-v4, glTF 2.0, OBJ/PLY meshes and the
 MIT 6.837 course format) with a physically based path tracer whose kernels run
 on OpenCL devices (GPUs, or CPUs through PoCL) and on a scalar C device built
 into the program, giving the same image bit for bit on any of them. The
 package holds the program, its man page, bash and zsh completions, and the C
 library libclpt with its header and pkg-config file.
CONTROL
# the libraries in /usr/lib need ldconfig run after install and removal
if ls "$stage"/usr/lib/libclpt.so.* >/dev/null 2>&1; then
    printf 'activate-noawait ldconfig\n' > "$stage/DEBIAN/triggers"
fi
dpkg-deb --root-owner-group -Zxz --build "$stage" "$build/$name.deb" >/dev/null
echo "$build/$name.deb"
