#!/bin/sh
# run_one.sh BUILD PROGRAM — runs one test program of the suite for tests/run.sh: prints
# its result line ("ok", "FAIL" with the log's FAIL lines, or "CRASH" with the log's
# tail) in one piece, so that lines of programs run side by side do not interleave,
# and leaves "PASSED FAILED SECONDS" in BUILD/tests/NAME.result for run.sh to add up.
# Each program prints its own "N passed, M failed" as its last line of stdout and its
# messages on stderr, kept as BUILD/tests/NAME.log.
set -u
build=$1
t=$2
name=$(basename "$t")
log="$build/tests/$name.log"
report="$build/tests/$name.report"
start=$(date +%s)
out=$("$t" 2>"$log")
rc=$?
: >"$report"
# LeakSanitizer's stop-the-world tracer sometimes crashes at exit ("Tracer caught
# signal 11", google/sanitizers#1353): the sanitizer failed, no leak was found, and
# the test's own summary was lost with the unflushed stdout. Seen once in about 20
# runs of test_kernels under ASan; then in a clpt process that test_cli ran, in
# three fresh-clone CI runs in a row (2026-11-26), the rerun passing each time, and
# in none of seven runs of test_cli alone. test_cli quotes the child's stderr in its
# failure message, after its own words: hence anywhere in a line. Such a run is
# repeated, at most twice; the failed run's log is kept as NAME.log.faultN and its
# fault line printed, to find out which clpt run it was.
tries=0
while [ "$rc" -ne 0 ] && [ "$tries" -lt 2 ] &&
    grep -q 'LeakSanitizer has encountered a fatal error' "$log" &&
    grep -q 'Tracer caught signal' "$log"; do
    tries=$((tries + 1))
    # keep the failed run's log, and say where the fault was
    cp "$log" "$log.fault$tries"
    {
        echo "RETRY $name: LeakSanitizer's tracer crashed at exit (a sanitizer fault, not a leak); running it again"
        grep -m 1 'Tracer caught signal' "$log" | cut -c 1-200 | sed 's/^/    /'
    } >>"$report"
    out=$("$t" 2>"$log")
    rc=$?
done
line=$(printf '%s\n' "$out" | tail -n 1)
p=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
f=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
secs=$(( $(date +%s) - start ))
if [ -z "$p" ]; then
    # crashed or printed no summary: count the whole program as one failure
    p=0; f=1
    {
        echo "CRASH $name (exit $rc, no summary line); log: $log"
        tail -n 20 "$log" | sed 's/^/    /'
    } >>"$report"
elif [ "$f" -ne 0 ] || [ "$rc" -ne 0 ]; then
    [ "$f" -eq 0 ] && f=1
    {
        echo "FAIL  $name: $line (${secs}s)"
        grep -E 'FAIL' "$log" | head -n 30 | sed 's/^/    /'
    } >>"$report"
else
    echo "ok    $name: $line (${secs}s)" >>"$report"
fi
echo "$p $f $secs" >"$build/tests/$name.result"
cat "$report"
rm -f "$report"
