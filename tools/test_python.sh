#!/bin/sh
# test_python.sh — the Python module's tests (python/tests, pytest) as one program of
# the suite: `make test` copies it to BUILD/tests/test_python, and tests/run.sh runs it
# from the repository's root like the others, reading its last line, "N passed, M failed".
#
# A virtual environment under BUILD/venv gets numpy, pytest and setuptools from PyPI
# once, then `pip install ./python` (which builds libclpt.so with `make lib`). The first
# install is the user's command, with pip's isolated build; later runs reinstall
# without it, which needs no network. Without PyPI the tests are skipped, saying so.
set -u
build=$(cd "$(dirname "$(dirname "$0")")" && pwd)
venv="$build/venv"
py="$venv/bin/python"
skip() {
    echo "test_python: SKIPPED: $1"
    echo "0 passed, 0 failed"
    exit 0
}
# A sanitizer build's libclpt.so needs the sanitizer runtime, which a Python process
# does not load; the C API is checked under the sanitizers by test_api instead.
[ -z "${ASAN_OPTIONS:-}" ] || skip "a sanitizer build (test_api covers the library there)"
fresh=0
if [ ! -x "$py" ]; then
    python3 -m venv "$venv" >&2 || skip "python3 -m venv failed (Debian: apt-get install python3-venv)"
    fresh=1
fi
if ! "$py" -c "import numpy, pytest, setuptools, wheel" 2>/dev/null; then
    "$py" -m pip install -q numpy pytest setuptools wheel >&2 ||
        skip "could not install numpy, pytest and setuptools from PyPI (no network?)"
    fresh=1
fi
if [ "$fresh" -eq 1 ]; then
    "$py" -m pip install -q ./python >&2
else
    "$py" -m pip install -q --no-build-isolation --no-deps --force-reinstall ./python >&2
fi || { echo "test_python: pip install ./python failed"; echo "0 passed, 1 failed"; exit 1; }
# from outside the repository, so that `import clpt` is the installed package
out=$(cd /tmp && "$py" -m pytest -q -p no:cacheprovider "$OLDPWD/python/tests" 2>&1)
rc=$?
printf '%s\n' "$out" >&2
last=$(printf '%s\n' "$out" | tail -n 1)
passed=$(printf '%s\n' "$last" | sed -n 's/.*\b\([0-9][0-9]*\) passed.*/\1/p')
failed=$(printf '%s\n' "$last" | sed -n 's/.*\b\([0-9][0-9]*\) failed.*/\1/p')
errors=$(printf '%s\n' "$last" | sed -n 's/.*\b\([0-9][0-9]*\) error.*/\1/p')
failed=$(( ${failed:-0} + ${errors:-0} ))
[ "$rc" -ne 0 ] && [ "$failed" -eq 0 ] && failed=1
echo "${passed:-0} passed, $failed failed"
[ "$failed" -eq 0 ]
