#!/bin/sh
# fuzz.sh BUILD SECONDS NAME... — runs each libFuzzer target BUILD/fuzz/fuzz_NAME for
# SECONDS (make fuzz; docs/fuzzing.md).
#
# Each target's corpus lives in BUILD/corpus/NAME (kept between runs, so later runs
# start where earlier ones stopped); it is seeded with the target's regression files
# (tests/data/fuzz/NAME/) and the files under tests/data/ and scenes/ whose extension
# is in the target's FUZZ_SEEDS("...") line; fuzz/fuzz_NAME.dict, when there is one, is
# its dictionary. A crash, leak, timeout (-timeout) or
# out-of-memory (-rss_limit_mb, -malloc_limit_mb) fails the run; the input is saved in
# BUILD/artifacts/NAME/. One line per target goes to BUILD/fuzz-report.txt: executions,
# seconds, executions per second, corpus size and the outcome.
set -u
build=$1
seconds=$2
shift 2
report="$build/fuzz-report.txt"
: > "$report"
failed=0
for name in "$@"; do
    bin="$build/fuzz/fuzz_$name"
    src="fuzz/fuzz_$name.c"
    corpus="$build/corpus/$name"
    seeds="$build/seeds/$name"
    artifacts="$build/artifacts/$name/"
    log="$build/fuzz-$name.log"
    rm -rf "$seeds"
    mkdir -p "$corpus" "$seeds" "$artifacts"
    exts=$(sed -n 's/^FUZZ_SEEDS("\(.*\)");.*/\1/p' "$src")
    for ext in $exts; do
        find tests/data scenes -path tests/data/fuzz -prune -o -type f -name "*.$ext" -print |
            while read -r f; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
    done
    [ -d "tests/data/fuzz/$name" ] && cp tests/data/fuzz/"$name"/* "$seeds/" 2>/dev/null
    # an optional dictionary, fuzz/fuzz_NAME.dict: the format's words, for mutations
    dict=""
    [ -f "fuzz/fuzz_$name.dict" ] && dict="-dict=fuzz/fuzz_$name.dict"
    start=$(date +%s)
    # -timeout: seconds for one input; -rss_limit_mb/-malloc_limit_mb: a parser that
    # allocates that much for inputs of a few kilobytes is a bug (limits before
    # allocation); -max_len: the longest seed (the shipped scenes) fits.
    "$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
        -max_len=8192 -print_final_stats=1 -artifact_prefix="$artifacts" $dict \
        "$corpus" "$seeds" >"$log" 2>&1
    rc=$?
    secs=$(( $(date +%s) - start ))
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    [ -n "$runs" ] || runs=0
    rate=$(( secs > 0 ? runs / secs : runs ))
    files=$(find "$corpus" -type f | wc -l)
    if [ "$rc" -eq 0 ]; then
        outcome=ok
    else
        outcome="FAILED (exit $rc): $(grep -m1 -E 'ERROR:|==ERROR|deadly signal|timeout|out-of-memory|leak' "$log")"
        failed=1
    fi
    line="fuzz_$name: $runs runs in ${secs} s ($rate/s), corpus $files files: $outcome"
    echo "$line" | tee -a "$report"
    if [ "$rc" -ne 0 ]; then
        echo "    log: $log; the input: $(ls "$artifacts" | sed "s|^|$artifacts|" | tr '\n' ' ')" >&2
        echo "    make it a regression file (docs/fuzzing.md): copy it to tests/data/fuzz/$name/, then fix" >&2
        tail -n 30 "$log" | sed 's/^/    /' >&2
    fi
done
[ "$failed" -eq 0 ]
