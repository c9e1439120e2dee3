#!/bin/sh
# check_exports.sh — libclpt.so exports the public interface and nothing else: every
# dynamic symbol it defines starts with clpt_ and is declared in include/clpt/clpt.h,
# and every function declared there is exported. Run by `make test`.
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
so="$build/libclpt.so"
[ -f "$so" ] || { echo "check_exports: $so is missing (make lib)" >&2; exit 1; }
# defined symbols only (U: undefined, from other libraries)
defined=$(nm -D --defined-only "$so" | awk '{print $3}' | sort -u)
declared=$(sed -n 's/^CLPT_API [^(]*[ *]\(clpt_[a-z0-9_]*\)(.*/\1/p' include/clpt/clpt.h | sort -u)
bad=0
for s in $defined; do
    case "$s" in
        _init|_fini|__bss_start|_edata|_end) continue ;;
    esac
    if ! printf '%s\n' "$declared" | grep -qx "$s"; then
        echo "check_exports: $so exports '$s', which include/clpt/clpt.h does not declare" >&2
        bad=1
    fi
done
for s in $declared; do
    if ! printf '%s\n' "$defined" | grep -qx "$s"; then
        echo "check_exports: include/clpt/clpt.h declares '$s', which $so does not export" >&2
        bad=1
    fi
done
soname=$(readelf -d "$so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
case "$soname" in
    libclpt.so.[0-9]*) ;;
    *) echo "check_exports: $so has SONAME '$soname', not libclpt.so.MAJOR" >&2; bad=1 ;;
esac
[ "$bad" -eq 0 ] && echo "check_exports: $so ($soname) exports the $(printf '%s\n' "$declared" | wc -l) functions of include/clpt/clpt.h, nothing else"
exit "$bad"
