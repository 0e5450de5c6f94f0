#!/bin/sh
# run.sh: replays the fuzz regression inputs, then fuzzes each harness for a while.
#   usage: sh tests/fuzz/run.sh HARNESS_DIR SECONDS WORK_DIR
# HARNESS_DIR holds the built harnesses (`make fuzz-build` puts them in build-fuzz/).
# For each harness NAME (fuzz_scene_parse, fuzz_expression, fuzz_obj_load, fuzz_gltf_load,
# fuzz_ply_load):
#   1. every file in tests/fuzz/regressions/NAME/ is run once: each once crashed;
#   2. NAME fuzzes for SECONDS, starting from its seed corpus (tests/fuzz/corpus/KIND/)
#      and the regressions; inputs it finds go to WORK_DIR/corpus/NAME/ (so a WORK_DIR
#      that is kept, as `make fuzz` keeps build-fuzz/, grows a corpus run after run),
#      a crashing input to WORK_DIR/artifacts/NAME/. Inputs are cut at 4096 bytes
#      (larger seeds too): at ten times the executions per second, that finds more.
# The harnesses fuzz at the same time (five processes on two cores in CI). Prints "PASS name" /
# "FAIL name: detail" lines and exits non-zero when any check failed.
set -u
harness_dir=$1
seconds=$2
work=$3
fuzz_dir=$(dirname "$0")
failures=0

pass() { echo "PASS $1"; }
fail() { echo "FAIL $1: $2"; failures=$((failures + 1)); }

# corpus_kind HARNESS: the seed corpus directory name of a harness.
corpus_kind() {
    case $1 in
        fuzz_scene_parse) echo scene ;;
        fuzz_expression) echo expression ;;
        fuzz_obj_load) echo obj ;;
        fuzz_gltf_load) echo gltf ;;
        fuzz_ply_load) echo ply ;;
    esac
}

# dictionary HARNESS: the libFuzzer dictionary of a harness's input language.
dictionary() {
    case $1 in
        fuzz_obj_load) echo "$fuzz_dir/obj.dict" ;;
        fuzz_gltf_load) echo "$fuzz_dir/gltf.dict" ;;
        fuzz_ply_load) echo "$fuzz_dir/ply.dict" ;;
        *) echo "$fuzz_dir/scene.dict" ;;
    esac
}

# report_crash NAME LOG: the sanitizer's or libFuzzer's one-line summary of a failure,
# and the input that caused it.
report_crash() {
    summary=$(grep -m1 -E '^SUMMARY: |ERROR: libFuzzer|==ERROR: ' "$2" || tail -n 1 "$2")
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$2" | head -n 1)
    echo "$summary${artifact:+ (input: $artifact)}"
}

harnesses="fuzz_scene_parse fuzz_expression fuzz_obj_load fuzz_gltf_load fuzz_ply_load"
for name in $harnesses; do
    if [ ! -x "$harness_dir/$name" ]; then
        fail "fuzz $name" "$harness_dir/$name is not built (make fuzz-build)"
        continue
    fi
    mkdir -p "$work/corpus/$name" "$work/artifacts/$name" "$work/logs"

    # 1. Regressions: libFuzzer runs each file given by name once.
    regressions=$(find "$fuzz_dir/regressions/$name" -type f ! -name '*.md' 2>/dev/null | sort)
    if [ -n "$regressions" ]; then
        count=$(echo "$regressions" | wc -l)
        log="$work/logs/$name-regressions.log"
        # shellcheck disable=SC2086 # one argument per file; the names have no spaces
        if "$harness_dir/$name" -timeout=20 -rss_limit_mb=2048 $regressions >"$log" 2>&1; then
            pass "fuzz $name: $count regression inputs"
        else
            fail "fuzz $name: regression inputs" "$(report_crash "$name" "$log")"
        fi
    fi

    # 2. Fuzzing, in the background; collected below.
    kind=$(corpus_kind "$name")
    seeds="$fuzz_dir/corpus/$kind"
    [ -d "$fuzz_dir/regressions/$name" ] && seeds="$seeds $fuzz_dir/regressions/$name"
    # shellcheck disable=SC2086 # $seeds is a list of directories without spaces
    "$harness_dir/$name" -max_total_time="$seconds" -max_len=4096 -timeout=20 -rss_limit_mb=2048 \
        -dict="$(dictionary "$name")" -print_final_stats=1 \
        -artifact_prefix="$work/artifacts/$name/" \
        "$work/corpus/$name" $seeds >"$work/logs/$name.log" 2>&1 &
    echo $! >"$work/logs/$name.pid"
done

for name in $harnesses; do
    [ -f "$work/logs/$name.pid" ] || continue
    if wait "$(cat "$work/logs/$name.pid")"; then status=0; else status=$?; fi
    rm -f "$work/logs/$name.pid"
    log="$work/logs/$name.log"
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    if [ "$status" = 0 ]; then
        pass "fuzz $name: ${runs:-?} inputs in $seconds s, no crash"
    else
        fail "fuzz $name" "exit $status after ${runs:-?} inputs: $(report_crash "$name" "$log") (log: $log)"
    fi
done

[ "$failures" = 0 ]
