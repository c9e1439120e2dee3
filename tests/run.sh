#!/bin/sh
# Runs every test program in BUILD/tests and prints the total: "N passed, M failed".
# tests/run_one.sh runs one program and prints its line; here they run side by side,
# TEST_JOBS at a time (default: the number of cores; TEST_JOBS=1 runs them one by one),
# the longest first, as the last run measured them (BUILD/tests/NAME.result), so that
# the slow ones do not end the run alone. Programs that have not run yet go first.
# Every program keeps its files in its own folder (tests/harness.h, test_tmp_path), so
# running them together shares nothing but the kernel caches, whose entries are written
# whole and renamed into place (docs/hardening.md).
set -u
build=${1:-build}
here=$(dirname "$0")
# PoCL compiles kernels on first use; keep its cache inside the build folder so test
# runs do not write to the user's home and reruns are fast.
case "$build" in /*) dir=$build ;; *) dir=$PWD/$build ;; esac
: "${POCL_CACHE_DIR:=$dir/pocl-cache}"
export POCL_CACHE_DIR
export CLPT_CACHE_DIR="${CLPT_CACHE_DIR:-$dir/kernel-cache}"
mkdir -p "$POCL_CACHE_DIR" "$CLPT_CACHE_DIR"
jobs=${TEST_JOBS:-$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)}
case "$jobs" in ''|*[!0-9]*|0) echo "run.sh: TEST_JOBS must be a positive number, not '$jobs'" >&2; exit 2 ;; esac

# "SECONDS PROGRAM" per program, the last run's seconds or a large number for one
# that has none, sorted longest first
order=$(for t in "$build"/tests/test_*; do
    [ -x "$t" ] || continue
    case "$t" in *.d|*.log|*.log.*|*.result|*.report) continue ;; esac
    secs=999999
    r="$build/tests/$(basename "$t").result"
    [ -f "$r" ] && secs=$(cut -d ' ' -f 3 "$r")
    case "$secs" in ''|*[!0-9]*) secs=999999 ;; esac
    echo "$secs $t"
done | sort -k1,1nr -k2,2 | cut -d ' ' -f 2-)
# one program per line: a build folder's name may hold spaces
IFS='
'
for t in $order; do rm -f "$build/tests/$(basename "$t").result"; done

printf '%s\n' "$order" | xargs -d '\n' -P "$jobs" -n 1 sh "$here/run_one.sh" "$build"

passed=0
failed=0
for t in $order; do
    r="$build/tests/$(basename "$t").result"
    if [ -f "$r" ]; then
        IFS=" " read -r p f _ <"$r"
    else
        # run_one.sh itself did not finish (killed): the program counts as one failure
        echo "LOST  $(basename "$t"): no result"
        p=0; f=1
    fi
    passed=$((passed + p))
    failed=$((failed + f))
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
