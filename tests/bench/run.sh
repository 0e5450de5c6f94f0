#!/bin/sh
# run.sh: `make bench`: times the benchmark scenes (not a test: nothing here passes or
# fails on speed). Prints a table and appends one CSV row per scene to build/bench.csv:
#   date,scene,size,spp,seconds,first_pass_seconds,samples_per_second,segments_per_second
# Knobs: BENCH_SPP (default 32) samples per pixel for the weekend scene.
#   usage: sh tests/bench/run.sh PROGRAM
set -eu
program=$1
spp=${BENCH_SPP:-32}
mkdir -p build/bench
csv=build/bench.csv
[ -f "$csv" ] || echo "date,scene,size,spp,seconds,samples_per_second,segments_per_second" >"$csv"

bench() {
    name=$1 scene=$2 size=$3 spp=$4
    shift 4
    out="build/bench/$name.exr"
    summary=$("$program" render "$scene" -o "$out" --size "$size" --spp "$spp" "$@" 2>&1 >/dev/null | tail -1)
    seconds=$(echo "$summary" | sed -n 's/.* spp in \([0-9.]*\) s .*/\1/p')
    samples=$(echo "$summary" | sed -n 's/.*(\([0-9.e+]*\) samples\/s.*/\1/p')
    segments=$(echo "$summary" | sed -n 's/.*, \([0-9.e+]*\) path segments\/s.*/\1/p')
    printf '%-12s %-10s %5s spp  %8s s  %10s samples/s  %10s segments/s\n' "$name" "$size" "$spp" "$seconds" "$samples" "$segments"
    echo "$(date -u +%Y-%m-%dT%H:%M:%SZ),$name,$size,$spp,$seconds,$samples,$segments" >>"$csv"
}

"$program" info | sed -n 's/^GL renderer: *//p' | sed 's/^/renderer: /'
bench weekend scenes/weekend.txt 1200x675 "$spp" --max-depth 50
bench three-balls scenes/three-balls.txt 640x360 64
echo "results appended to $csv"
