#!/bin/sh
# run.sh: `make bench` (issue #6): times a fixed set of scenes and a plain C reference in
# the same run, and reports rtspheres' speed as ratios to it. Not a test: nothing here
# passes or fails on speed (the exit status is 1 only when a render itself failed).
#
#   usage: sh tests/bench/run.sh PROGRAM          (from the repository root)
#
# Does not build rtspheres (the Makefile does); compiles its own tools into build/bench/
# with $CC / $CXX: the reference (tests/bench/reference_weekend.c, -O3 -march=native
# -fopenmp, on purpose without your CFLAGS: it is a fixed yardstick), the peak-RSS
# wrapper (peak_rss.c), the chart (plot.cpp, OpenImageIO) and the mesh generator.
#
# The set (sizes and spp as run by default):
#   startup, startup-cached  weekend at 64x36, 1 spp: the command's start in main (after the
#                  dynamic loader's 0.2 s, docs/performance.md "Ideas"; the summary gives
#                  the cold start from the process's start too) to the first finished
#                  pass with Mesa's shader cache off (a first run: context, parse, BVH,
#                  upload and the whole shader compile; the issue's "cold start") and on
#   weekend        scenes/weekend.txt 1200x675, BENCH_SPP spp, depth 50, and right after
#   reference-weekend  the plain C reference of the same scene (same samples, depth 50)
#   three-balls    640x360, 16 spp; three-balls-whitted the same frame, 4 spp, Whitted
#   three-balls-anim  24 frames (--frames 0-23) at 320x180, 4 spp, one GPU context
#   lights, lights-groups  scenes/lights.txt 640x360, 16 spp, without and with
#                  --light-groups, BENCH_ROUNDS rounds (rows -2, -3, ...: issue 15's ratio
#                  is the median of the pairs' ratios)
#   cornell        600x600, 4 spp; next-week 400x400 (half the book's), 2 spp;
#   crystal-ball   640x480, 4 spp
#   pbr-chart      scenes/pbr-chart.txt 640x360, 16 spp: the pbr material, every
#                  roughness and metallic (issue 14)
#   denoise-1080p  `rtspheres denoise` of a three-balls 1920x1080 4-spp --aovs render
#                  (the render untimed): the denoiser's speed for a frame, the EXR's
#                  reading and writing in it
#   panorama-20000, square-16384  three-balls at 20000x2000 (wider than the device) and
#                  16384x16384 (depth 2), 1 spp, in tiles (issue 17: peak RSS targets)
#   full-hd, full-hd-untiled  three-balls 1920x1080, 1 spp, with the default budget and
#                  with one that never tiles: resident memory must not grow
#   mesh-L         icospheres of level L (3 5 6 8: 1,280 / 20,480 / 81,920 / 1,310,720
#                  triangles, the nearest levels to the issue's 1k/10k/100k/1M), 320x240,
#                  16 spp, depth 8
#   gltf-model     model.glb of scenes/generators/models.c (its camera, lights, textures),
#                  320x213, 16 spp
#   gltf-1M, ply-1M  a torus of 1,000,064 triangles as .glb and as binary PLY
#                  (scenes/generators/models.c DIR big), framed as mesh-L, 320x240, 16
#                  spp; their note is tests/bench/import_time.c's load and pack seconds
#                  (issue 14's target: under 3 s, at most 100 packed bytes per triangle)
# About 2 minutes on 2 idle cores, 5 with a test run alongside; most of it the weekend.
#
# Columns: wall s (the whole process, from peak_rss), cores (its CPU time / wall time:
# below the core count when other work took CPU), render s (rtspheres' own time:
# from the BVH build to the last pass, so BVH build, upload and shader compile are in it;
# the reference: its render loop), samples/s, path segments/s (counted by the shader
# and by the reference, one per ray from the camera or a bounce), us/sample (the passes
# after the first, over the samples they finished, as rtspheres --verbose reports it: the
# cost of a sample once set-up is done; BVH build, packing, upload and compile are
# one-off costs with columns of their own, whose share would otherwise depend on the
# spp), BVH s, B/tri (packed bytes per triangle), first pass s (process start to the
# first finished pass), RSS MiB (peak resident set, the process with all its threads).
#
# Outputs:
#   stdout            one table row per scene as it finishes, then the targets as ratios
#   build/bench.csv   one row per scene per run, appended (a file with another header is
#                     moved aside to build/bench-old-DATE.csv first)
#   build/bench.json  the latest run: machine, knobs, every scene, reference, targets
#   build/bench-plot.png  time per sample against triangle count (log x)
#   build/bench/      images, logs (NAME.log) and tools
#
# Knobs (environment):
#   BENCH_SPP            weekend samples per pixel (default 32)
#   BENCH_REFERENCE_SPP  the reference's samples per pixel (default 8; a rate is compared,
#                        so fewer samples only make it noisier)
#   BENCH_SCALE          multiplies the spp of every other scene (default 1; 0.25 for a
#                        quick look, integer results, at least 1 spp)
#   BENCH_MESH_LEVELS    icosphere levels (default "3 5 6 8"; 20 * 4^level triangles)
#   BENCH_LARGE          0: leave out the large images of issue 17 (panorama-20000,
#                        square-16384, full-hd, full-hd-untiled), which take most of the
#                        run's memory and, at 1 spp, a few minutes on idle cores
#   BENCH_ROUNDS         rounds of the renders behind the targets that are ratios of two
#                        renders of a second or two (light groups; adaptive sampling,
#                        tests/bench/peers.sh), whose median the target takes (default 5:
#                        within one run of three the adaptive Cornell box's rounds spread
#                        from 0.405 to 0.533, docs/performance.md)
set -eu
program=$1
weekend_spp=${BENCH_SPP:-32}
reference_spp=${BENCH_REFERENCE_SPP:-8}
scale=${BENCH_SCALE:-1}
mesh_levels=${BENCH_MESH_LEVELS:-3 5 6 8}
large=${BENCH_LARGE:-1}
rounds=${BENCH_ROUNDS:-5}
case $rounds in
    '' | *[!0-9]* | 0) echo "run.sh: BENCH_ROUNDS must be a whole number of at least 1, not '$rounds'" >&2; exit 2 ;;
esac
CC=${CC:-cc}
CXX=${CXX:-c++}
work=build/bench
csv=build/bench.csv
json=build/bench.json
chart=build/bench-plot.png
rows=$work/run.tsv       # this run's rows, tab-separated, for the summary and the JSON
mkdir -p "$work"
: >"$rows"
run_id=$(date -u +%Y-%m-%dT%H:%M:%SZ)
failures=0

header="date,run,scene,size,spp,frames,triangles,wall_seconds,render_seconds,samples_per_second,segments_per_second,seconds_per_sample,bvh_build_seconds,bytes_per_triangle,first_pass_seconds,peak_rss_mib,frames_per_second,cpu_seconds,renderer,rmse"
if [ -f "$csv" ] && [ "$(head -n 1 "$csv")" != "$header" ]; then
    old="build/bench-old-$(date -u +%Y%m%dT%H%M%SZ).csv"
    mv "$csv" "$old"
    echo "bench: $csv had other columns; moved it to $old"
fi
[ -f "$csv" ] || echo "$header" >"$csv"

# ---- tools ----------------------------------------------------------------------------
# Builds OUTPUT from SOURCE with the command in the rest of the arguments unless OUTPUT
# is newer already; says so as the Makefile does (the command itself with V=1).
build_tool() {
    tool_output=$1 tool_source=$2
    shift 2
    [ -n "$(find "$tool_output" -newer "$tool_source" 2>/dev/null)" ] && return 0
    if [ "${V:-}" = 1 ]; then echo "$@"; else printf '  %-7s %s\n' TOOL "$tool_output"; fi
    "$@" || { echo "bench: building $tool_output failed" >&2; exit 1; }
}
build_tool "$work/peak_rss" tests/bench/peak_rss.c \
    "$CC" -std=c11 -Wall -Wextra -O2 tests/bench/peak_rss.c -o "$work/peak_rss"
build_tool "$work/reference_weekend" tests/bench/reference_weekend.c \
    "$CC" -std=c11 -Wall -Wextra -O3 -march=native -fopenmp tests/bench/reference_weekend.c -lm \
    -o "$work/reference_weekend"
# shellcheck disable=SC2046 # pkg-config prints several flags, to be split into words
build_tool "$work/plot" tests/bench/plot.cpp \
    "$CXX" -std=c++17 -Wall -Wextra -O2 $(pkg-config --cflags OpenImageIO) tests/bench/plot.cpp \
    $(pkg-config --libs OpenImageIO) -o "$work/plot"
build_tool "$work/assets" scenes/generators/assets.c \
    "$CC" -std=c11 -O2 scenes/generators/assets.c -lm -o "$work/assets"
build_tool "$work/models-generator" scenes/generators/models.c \
    "$CC" -std=c11 -O2 scenes/generators/models.c -lm -o "$work/models-generator"
# The import timer links the library the Makefile built (make bench builds it first).
# shellcheck disable=SC2046 # pkg-config prints several flags, to be split into words
build_tool "$work/import_time" tests/bench/import_time.c \
    "$CC" -std=c11 -D_GNU_SOURCE -Wall -Wextra -O2 -Icore tests/bench/import_time.c build/librtspheres.a \
    $(pkg-config --libs epoxy egl OpenImageIO tinyobjloader tinygltf cglm) -lstdc++ -lm -o "$work/import_time"

# ---- measuring ------------------------------------------------------------------------
# Prints N scaled by BENCH_SCALE, rounded, at least 1.
scaled() { awk -v n="$1" -v s="$scale" 'BEGIN { v = int(n * s + 0.5); print v < 1 ? 1 : v }'; }

# Prints the first match of sed expression $2 in text $1, or "-" when there is none.
field() { found=$(printf '%s\n' "$1" | sed -n "$2" | head -n 1); echo "${found:--}"; }

# Appends one row to the run's rows and the CSV and prints it in the table. Arguments
# (their column numbers in the rows): 1 name, 2 size, 3 spp, 4 frames, 5 triangles,
# 6 wall s, 7 render s, 8 samples/s, 9 segments/s, 10 s/sample, 11 BVH s, 12 B/tri,
# 13 first pass s, 14 RSS MiB, 15 frames/s, 16 CPU s, 17 note, 18 renderer (rtspheres when
# left out), 19 RMSE against the row's quality reference (tests/bench/peers.sh); "-" when
# unknown.
record() {
    printf '%s\t' "$@" | sed 's/\t$//' >>"$rows"
    [ $# -ge 18 ] || printf '\trtspheres' >>"$rows"
    [ $# -ge 19 ] || printf '\t-' >>"$rows"
    echo >>"$rows"
    printf '%-22s %-8s %3s %9s %7s %5s %8s %9s %10s %8s %6s %6s %6s %5s  %s\n' \
        "$1" "$2" "$3" "$5" "$6" "$(awk -v c="${16}" -v w="$6" 'BEGIN {
            if (c == "-" || w == "-" || w <= 0) print "-"; else printf "%.2f", c / w }')" "$7" "$8" "$9" \
        "$(awk -v s="${10}" 'BEGIN { if (s == "-") print "-"; else printf "%.3g", s * 1e6 }')" \
        "${11}" "${12}" "${13}" "${14}" "${17}"
    # The CSV leaves unknown values empty rather than "-", and has no note.
    echo "$(date -u +%Y-%m-%dT%H:%M:%SZ),$run_id,$1,$2,$3,$4,$5,$6,$7,$8,$9,${10},${11},${12},${13},${14},${15},${16},${18:-rtspheres},${19:--}" |
        awk -F ',' 'BEGIN { OFS = "," } { for (i = 1; i <= NF; i++) if ($i == "-") $i = ""; print }' >>"$csv"
}

# Renders SCENE as NAME under the peak-RSS wrapper and records its row with NOTE; the
# arguments after NOTE go to rtspheres. $render_environment (NAME=VALUE words, usually
# empty) is added to rtspheres' environment. With $quality_reference set (an image of
# the same size, tests/bench/peers.sh), the row also gets the RMSE against it.
render_environment=
bench() {
    name=$1 scene=$2 size=$3 spp=$4 note=$5
    shift 5
    out="$work/$name.exr" log="$work/$name.log"
    rm -f "$out"     # a failed render must not leave the last run's image to be measured
    # First an untimed 8x8 render with the row's options, so that Mesa's shader cache holds
    # this variant's machine code: else the first run on a machine (or after a Mesa update)
    # times each variant's compile inside its first row (docs/performance.md, the fourth
    # machine's first run). The start-up probes time exactly that, so they are not warmed.
    case $name in
    startup*) ;;
    *) env $render_environment "$program" render "$scene" -o "$work/warm-up.exr" --size 8x8 --spp "$spp" --quiet \
        "$@" >/dev/null 2>&1 || : ;;
    esac
    if ! env $render_environment "$work/peak_rss" "$program" render "$scene" -o "$out" --size "$size" --spp "$spp" \
        --verbose "$@" 2>"$log" >/dev/null; then
        echo "$name: rtspheres FAILED (exit status in $log:)"; tail -n 3 "$log"
        failures=$((failures + 1))
        return 0
    fi
    summary=$(grep -- "-> $out" "$log" | tail -n 1)
    details=$(grep "rtspheres: scene:" "$log" | tail -n 1)
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    # Render s from the image's metadata, to the microsecond: the summary line rounds to
    # 0.01 s, which moved the adaptive rows' ratios of 0.2 s renders by up to 5%.
    render_seconds=$("$program" stats "$out" 2>/dev/null | sed -n 's/^metadata rtspheres:render_seconds: //p' |
        awk 'NR == 1 { printf "%.4f", $1 }')
    [ -n "$render_seconds" ] || render_seconds=$(field "$summary" 's/.* spp in \([0-9.]*\) s .*/\1/p')
    samples=$(field "$summary" 's/.*(\([0-9.e+-]*\) samples\/s.*/\1/p')
    segments=$(field "$summary" 's/.*, \([0-9.e+-]*\) path segments\/s.*/\1/p')
    triangles=$(field "$details" 's/.*(\([0-9]*\) triangles).*/\1/p')
    build=$(field "$details" 's/.*built in \([0-9.]*\) s.*/\1/p')
    per_triangle=$(field "$details" 's/.*bytes (\([0-9.]*\) per triangle.*/\1/p')
    [ "$triangles" != 0 ] || per_triangle=-
    first=$(field "$details" 's/.*first pass done \([0-9.]*\) s.*/\1/p')
    wall=$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')
    cpu=$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    rss=$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')
    # Time per sample: the passes after the first over the samples they finished
    # (rtspheres --verbose); without it, the render time less the BVH build over all
    # samples (not from the rounded rate).
    steady=$(field "$details" 's/.*after it \([0-9.]*\) s for \([0-9]*\) samples.*/\1 \2/p')
    per_sample=$(awk -v s="$render_seconds" -v b="$build" -v size="$size" -v spp="$spp" -v steady="$steady" 'BEGIN {
        split(size, wh, "x"); if (b == "-") b = 0; split(steady, st, " ")
        if (steady != "-" && st[2] > 0) printf "%.4g", st[1] / st[2]
        else if (s == "-") print "-"; else printf "%.4g", (s - b) / (wh[1] * wh[2] * spp) }')
    rmse=$(image_rmse "$out")
    [ "$rmse" = - ] || note="${note:+$note; }RMSE $rmse"
    record "$name" "$size" "$spp" 1 "$triangles" "$wall" "$render_seconds" "$samples" "$segments" "$per_sample" \
        "$build" "$per_triangle" "$first" "$rss" - "$cpu" "$note" rtspheres "$rmse"
}

# Times a sweep of ROWS rows of the three balls' light at SIZE and SPP (issue 15): one
# `render --sweep` against ROWS separate renders of the same rows, wall seconds each, as
# the rows sweep-ROWS (the sweep) and sweep-ROWS-separate (the renders together).
bench_sweep() {
    sweep_rows=$1 size=$2 spp=$3
    table=$work/sweep.tsv
    printf 'light_x\tlight_z\n' >"$table"
    i=0
    while [ "$i" -lt "$sweep_rows" ]; do
        printf '4*cos(2*pi*%d/%d)\t4*sin(2*pi*%d/%d)\n' "$i" "$sweep_rows" "$i" "$sweep_rows" >>"$table"
        i=$((i + 1))
    done
    start=$(date +%s.%N)
    "$program" render scenes/three-balls.txt -o "$work/sweep-%02d.exr" --sweep "$table" --size "$size" --spp "$spp" \
        --quiet || failures=$((failures + 1))
    middle=$(date +%s.%N)
    i=0
    while [ "$i" -lt "$sweep_rows" ]; do
        "$program" render scenes/three-balls.txt -o "$work/separate-$i.exr" --size "$size" --spp "$spp" --quiet \
            -D "light_x=4*cos(2*pi*$i/$sweep_rows)" -D "light_z=4*sin(2*pi*$i/$sweep_rows)" || failures=$((failures + 1))
        i=$((i + 1))
    done
    end=$(date +%s.%N)
    sweep_wall=$(awk -v a="$start" -v b="$middle" 'BEGIN { printf "%.3f", b - a }')
    separate_wall=$(awk -v a="$middle" -v b="$end" 'BEGIN { printf "%.3f", b - a }')
    record "sweep-$sweep_rows" "$size" "$spp" "$sweep_rows" 0 "$sweep_wall" - - - - - - - - - - "--sweep, one process"
    record "sweep-$sweep_rows-separate" "$size" "$spp" "$sweep_rows" 0 "$separate_wall" - - - - - - - - - - \
        "$sweep_rows separate renders"
}

# Times `rtspheres denoise` of a 1920x1080 4-spp --aovs render of the three balls (its
# render untimed) under the peak-RSS wrapper as NAME: a frame's denoising, reading and
# writing its EXR included (3.7-3.9 s before the denoiser's vector loops and PIZ,
# docs/performance.md, the log).
bench_denoise() {
    name=$1
    input="$work/$name-input.exr" out="$work/$name.exr" log="$work/$name.log"
    rm -f "$out"
    if ! "$program" render scenes/three-balls.txt -o "$input" --size 1920x1080 --spp 4 --aovs --quiet \
        >"$log" 2>&1 || ! "$work/peak_rss" "$program" denoise "$input" -o "$out" --quiet 2>"$log" >/dev/null; then
        echo "$name: rtspheres FAILED (see $log:)"; tail -n 3 "$log"
        failures=$((failures + 1))
        return 0
    fi
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    record "$name" 1920x1080 4 1 0 "$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')" - - - - - - - \
        "$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')" - \
        "$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')" "rtspheres denoise of a 4-spp --aovs render"
}

# Renders the three-ball animation (frames 0 .. FRAMES-1 on one GPU context) as NAME and
# records its row: rates over all frames, first pass and BVH of the first frame.
bench_animation() {
    name=$1 scene=$2 size=$3 spp=$4 frames=$5
    log="$work/$name.log"
    rm -f "$work/$name"-*.exr
    if ! "$work/peak_rss" "$program" render "$scene" -o "$work/$name-%03d.exr" --size "$size" --spp "$spp" \
        --frames "0-$((frames - 1))" --verbose 2>"$log" >/dev/null; then
        echo "$name: rtspheres FAILED (see $log:)"; tail -n 3 "$log"
        failures=$((failures + 1))
        return 0
    fi
    details=$(grep "rtspheres: scene:" "$log" | head -n 1)
    summary=$(grep "frames in .* frames/s" "$log" | tail -n 1)
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    seconds=$(field "$summary" 's/.* frames* in \([0-9.]*\) s .*/\1/p')
    fps=$(field "$summary" 's/.*(\([0-9.e+-]*\) frames\/s).*/\1/p')
    # Path segments: each frame's rate times its time, summed over the frames.
    segments_total=$(grep -- "-> $work/$name-" "$log" |
        sed -n 's/.* spp in \([0-9.]*\) s (.*, \([0-9.e+-]*\) path segments\/s.*/\1 \2/p' |
        awk '{ total += $1 * $2 } END { print total + 0 }')
    rates=$(awk -v s="$seconds" -v size="$size" -v spp="$spp" -v n="$frames" -v seg="$segments_total" 'BEGIN {
        split(size, wh, "x"); samples = wh[1] * wh[2] * spp * n
        if (s == "-" || s <= 0) print "- - -"; else printf "%.3g %.3g %.4g\n", samples / s, seg / s, s / samples }')
    # shellcheck disable=SC2086 # three numbers (or dashes), one argument each
    set -- $rates
    wall=$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')
    cpu=$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    rss=$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')
    record "$name" "$size" "$spp" "$frames" 0 "$wall" "$seconds" "$1" "$2" "$3" \
        "$(field "$details" 's/.*built in \([0-9.]*\) s.*/\1/p')" - \
        "$(field "$details" 's/.*first pass done \([0-9.]*\) s.*/\1/p')" "$rss" "$fps" "$cpu" \
        "$fps frames/s ($frames frames)"
}

# Renders the weekend scene with the plain C reference and records its row.
bench_reference() {
    size=$1 spp=$2
    log="$work/reference-weekend.log"
    if ! "$work/peak_rss" "$work/reference_weekend" scenes/weekend.txt -o "$work/reference-weekend.pfm" \
        --size "$size" --spp "$spp" --max-depth 50 >"$log" 2>&1; then
        echo "reference-weekend: FAILED (see $log:)"; tail -n 3 "$log"
        failures=$((failures + 1))
        return 0
    fi
    summary=$(grep "^reference:" "$log" | tail -n 1)
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    seconds=$(field "$summary" 's/.* spp in \([0-9.]*\) s .*/\1/p')
    threads=$(field "$summary" 's/.*, \([0-9]*\) threads).*/\1/p')
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    rss=$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')
    per_sample=$(awk -v s="$seconds" -v size="$size" -v spp="$spp" 'BEGIN {
        split(size, wh, "x"); if (s == "-") print "-"; else printf "%.4g", s / (wh[1] * wh[2] * spp) }')
    record reference-weekend "$size" "$spp" 1 0 "$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')" \
        "$seconds" "$(field "$summary" 's/.*(\([0-9.e+-]*\) samples\/s.*/\1/p')" \
        "$(field "$summary" 's/.*, \([0-9.e+-]*\) path segments\/s.*/\1/p')" "$per_sample" - - - "$rss" - \
        "$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')" "plain C, brute force, OpenMP $threads threads"
}

# Prints the value of KEY ($2) in this run's time-to-quality results of LABEL ($1), or "-".
quality_value() {
    awk -F '\t' -v label="$1" -v key="$2" '$1 == label && $2 == key { v = $3 } END { print v == "" ? "-" : v }' \
        "$quality"
}

# Prints column $2 of the row named $1 of this run, or "-".
value() {
    awk -F '\t' -v name="$1" -v column="$2" '$1 == name { v = $column } END { print v == "" ? "-" : v }' "$rows"
}

# The peers' rows (Blender Cycles, POV-Ray) and time to quality: tests/bench/peers.sh.
# shellcheck source=tests/bench/peers.sh
. tests/bench/peers.sh

# ---- the run --------------------------------------------------------------------------
renderer=$("$program" info 2>/dev/null | sed -n 's/^GL renderer: *//p')
cpu_model=$(sed -n 's/^model name[[:space:]]*: *//p' /proc/cpuinfo 2>/dev/null | head -n 1)
cores=$(nproc 2>/dev/null || echo "-")
load_start=$(cut -d ' ' -f 1-3 /proc/loadavg 2>/dev/null || echo "-")
echo "bench: $run_id, $cpu_model, $cores cores, renderer $renderer"
echo "bench: load average at the start $load_start (other work on the machine slows both renderers alike" \
    "only when it stays steady)"
printf '%-22s %-8s %3s %9s %7s %5s %8s %9s %10s %8s %6s %6s %6s %5s  %s\n' \
    scene size spp triangles "wall s" cores "render s" samples/s segments/s us/sample "BVH s" B/tri "first" "RSS" note
printf '%-22s %-8s %3s %9s %7s %5s %8s %9s %10s %8s %6s %6s %6s %5s\n' \
    "" "" "" "" "" "" "" "" "" "" "" "" "pass s" "MiB"

# The start-up probe: with Mesa's on-disk shader cache off, every run compiles the tracer
# from scratch, as a first run on a new machine does.
render_environment=MESA_SHADER_CACHE_DISABLE=true
bench startup scenes/weekend.txt 64x36 1 "start-up probe: Mesa shader cache off" --max-depth 50
render_environment=
# The same with the cache as later runs find it (one unrecorded run fills it first).
"$program" render scenes/weekend.txt -o "$work/startup-cached.exr" --size 64x36 --spp 1 --quiet 2>/dev/null || :
bench startup-cached scenes/weekend.txt 64x36 1 "start-up probe: Mesa shader cache on" --max-depth 50
# The headline pair back to back, so that the same load weighs on both.
bench weekend scenes/weekend.txt 1200x675 "$weekend_spp" "" --max-depth 50
bench_reference 1200x675 "$reference_spp"
# The peer at equal spp, right after them (issue 13: rtspheres at most half its time).
if peer_ready cycles; then
    bench_cycles cycles-weekend scenes/weekend.txt 1200x675 "$weekend_spp" "" --max-depth 50
fi
bench three-balls scenes/three-balls.txt 640x360 "$(scaled 16)" ""
# The seed's quick-sweep mode: a Whitted frame with soft shadows, and right after it the
# same frame in POV-Ray with an 8x8 area light (tests/bench/peers.sh).
bench three-balls-whitted scenes/three-balls.txt 640x360 4 "Whitted" --integrator whitted
if peer_ready povray; then
    bench_povray povray-three-balls scenes/three-balls.txt 640x360 16
fi
bench_animation three-balls-anim scenes/three-balls.txt 320x180 "$(scaled 4)" 24
# Light groups (issue 15): lights.txt's four lights in four groups (and the sky in
# default), with and without their layers, back to back, $rounds rounds: the ratio of one
# pair of these 2-second renders moved from 0.94 to 1.20 between runs of the same binary
# (docs/performance.md), so the target takes the median of the pairs' ratios.
for round in $(seq 1 "$rounds"); do
    suffix=$([ "$round" = 1 ] || echo "-$round")
    bench "lights$suffix" scenes/lights.txt 640x360 "$(scaled 16)" ""
    bench "lights-groups$suffix" scenes/lights.txt 640x360 "$(scaled 16)" "--light-groups, 5 layers" --light-groups
done
bench_sweep 12 320x180 "$(scaled 4)"
# The books' scenes at the books' sizes, except the Next Week scene at half its 800x800
# (its fog makes every path scatter: 1 spp of the full frame takes ~40 s here).
bench cornell scenes/cornell.txt 600x600 "$(scaled 4)" ""
bench next-week scenes/next-week.txt 400x400 "$(scaled 2)" ""
bench crystal-ball scenes/crystal-ball.txt 640x480 "$(scaled 4)" ""
# The pbr material (issue 14): a chart of roughness by metallic under a sphere light.
bench pbr-chart scenes/pbr-chart.txt 640x360 "$(scaled 16)" ""
bench_denoise denoise-1080p
# Any image size in bounded memory (issue 17): a panorama wider than the device's 16384
# pixels, a 16384-pixel square at depth 2 (both in tiles, the default --memory-budget),
# and a plain 1920x1080 as it renders by default and with a budget that never tiles it:
# its resident memory must not grow with tiling. BENCH_LARGE=0 leaves them out.
if [ "$large" != 0 ]; then
    bench panorama-20000 scenes/three-balls.txt 20000x2000 1 "tiles; target peak RSS < 1536 MiB"
    bench square-16384 scenes/three-balls.txt 16384x16384 1 "tiles, depth 2; target peak RSS < 2048 MiB" \
        --max-depth 2
    bench full-hd scenes/three-balls.txt 1920x1080 1 "default budget"
    bench full-hd-untiled scenes/three-balls.txt 1920x1080 1 "--memory-budget 64G: never tiled" \
        --memory-budget 64G
fi

# Time to quality against Cycles (tests/bench/peers.sh): ladders of spp, RMSE against
# each renderer's own cached high-spp reference. The issue's sizes: the Cornell box at
# 200x200 with depth 50, three balls at 320x180 with the scene's depth 16.
quality_scene cornell scenes/cornell.txt 200x200 50
quality_scene three-balls scenes/three-balls.txt 320x180 16

# Meshes of growing size, the same small frame each: time per sample should grow about
# like log n. Generated at run time (the largest OBJ is 138 MB), never committed.
for level in $mesh_levels; do
    [ -f "$work/icosphere-$level.obj" ] || "$work/assets" "$work" "$level" >/dev/null
    cat >"$work/mesh-$level.txt" <<SCENE
render size 320 240 depth 8 seed 1
camera from 0 0.5 3.2 at 0 0 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.5 0.7 1
material ground lambertian 0.5 0.5 0.5
material shiny metal 0.9 0.8 0.7 fuzz 0.2
sphere 0 -1001 0 1000 ground
group material shiny {
    mesh "icosphere-$level.obj"
}
SCENE
    bench "mesh-$level" "$work/mesh-$level.txt" 320x240 "$(scaled 16)" ""
done

# Imported files (issue 14): a glTF scene by itself, and a million triangles as glTF and
# PLY, each first timed loading and packing (import_time), then rendered.
"$work/models-generator" "$work/models" >/dev/null
bench gltf-model "$work/models/model.glb" 320x213 "$(scaled 16)" ""
[ -f "$work/models/big.glb" ] || "$work/models-generator" "$work/models" big 1000000 >/dev/null
cat >"$work/models/ply-1M.txt" <<'SCENE'
render size 320 240 depth 8 seed 1
camera from 0 2 3.2 at 0 0 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.5 0.7 1
material shiny metal 0.9 0.8 0.7 fuzz 0.2
mesh "big.ply" shiny
SCENE
import_note() {
    if "$work/import_time" "$1" >"$work/$2-import.log" 2>&1; then
        sed -n 's/^import: [^:]*: \(load .*\); .*/\1/p' "$work/$2-import.log"
    else
        echo "import_time FAILED"
    fi
}
gltf_import=$(import_note "$work/models/big.glb" gltf-1M)
ply_import=$(import_note "$work/models/ply-1M.txt" ply-1M)
bench gltf-1M "$work/models/big.glb" 320x240 "$(scaled 16)" "$gltf_import"
bench ply-1M "$work/models/ply-1M.txt" 320x240 "$(scaled 16)" "$ply_import"
load_end=$(cut -d ' ' -f 1-3 /proc/loadavg 2>/dev/null || echo "-")

# ---- the weekend images agree? (a sanity check of the reference, never a failure) ------
rtspheres_mean=$("$program" stats "$work/weekend.exr" 2>/dev/null |
    awk '/^channel [RGB]:/ { printf "%s%.4f", n++ ? " " : "", $4 }')
reference_mean=$(sed -n 's/.*; mean \(.*\)$/\1/p' "$work/reference-weekend.log" 2>/dev/null | tail -n 1)
mean_difference=$(echo "${rtspheres_mean:--} ${reference_mean:--}" | awk 'NF == 6 {
    for (i = 1; i <= 3; i++) { d = ($i - $(i + 3)) / ($i > 0 ? $i : 1); d = d < 0 ? -d : d; if (d > m) m = d }
    printf "%.2g", 100 * m; exit } { print "-" }')
echo
echo "weekend mean colour: rtspheres ${rtspheres_mean:--}, reference ${reference_mean:--}" \
    "(largest difference ${mean_difference}%; same scene when within about 1%)"

# ---- the peers (issue 13): equal spp, time to quality ------------------------------------
echo
if [ "$(value cycles-weekend 7)" != - ]; then
    cycles_mean=$("$work/image_error" "$work/cycles-weekend.exr" 2>/dev/null | sed -n 's/^mean //p')
    echo "weekend at $weekend_spp spp: rtspheres render $(value weekend 7) s, Cycles render call" \
        "$(value cycles-weekend 7) s ($(ratio "$(value weekend 7)" "$(value cycles-weekend 7)")x); whole processes" \
        "$(value weekend 6) s and $(value cycles-weekend 6) s ($(ratio "$(value weekend 6)" "$(value cycles-weekend 6)")x);" \
        "their CPU s (all threads; less moved by other work) $(value weekend 16) and $(value cycles-weekend 16)" \
        "($(ratio "$(value weekend 16)" "$(value cycles-weekend 16)")x); Cycles' mean colour ${cycles_mean:--}"
fi
if [ "$(value povray-three-balls 7)" != - ]; then
    echo "three balls, Whitted, 640x360: rtspheres 4 spp render $(value three-balls-whitted 7) s (whole process" \
        "$(value three-balls-whitted 6) s), POV-Ray trace $(value povray-three-balls 7) s (whole process" \
        "$(value povray-three-balls 6) s): $(ratio "$(value three-balls-whitted 7)" "$(value povray-three-balls 7)")x"
fi
quality_compare cornell
quality_compare three-balls
printf '%s' "$peer_notes"

# ---- the chart --------------------------------------------------------------------------
plot_data=$work/plot-data.txt
echo "# triangles seconds_per_sample name (make bench, $run_id)" >"$plot_data"
for level in $mesh_levels; do
    awk -F '\t' -v name="mesh-$level" '$1 == name && $5 != "-" && $10 != "-" { print $5, $10, $1 }' \
        "$rows" >>"$plot_data"
done
if [ "$(grep -vc '^#' "$plot_data")" -gt 0 ] && "$work/plot" "$plot_data" "$chart"; then
    echo "chart: $chart (time per sample against triangles; data in $plot_data)"
else
    echo "chart: not drawn"
fi

# ---- targets (issue #6) -------------------------------------------------------------------
first_level=$(echo "$mesh_levels" | awk '{ print $1 }')
last_level=$(echo "$mesh_levels" | awk '{ print $NF }')
targets=$work/targets.tsv
{
    # name, value, comparison, limit, unit, how it is computed
    printf 'weekend_segments_ratio\t%s\t>=\t3\tx\tweekend path segments/s / reference path segments/s\n' \
        "$(awk -v a="$(value weekend 9)" -v b="$(value reference-weekend 9)" 'BEGIN {
            if (a == "-" || b == "-" || b <= 0) print "-"; else printf "%.3g", a / b }')"
    printf 'mesh_time_per_sample_growth\t%s\t<=\t2.5\tx\ttime per sample mesh-%s / mesh-%s (set-up apart)\n' \
        "$(awk -v a="$(value "mesh-$last_level" 10)" -v b="$(value "mesh-$first_level" 10)" 'BEGIN {
            if (a == "-" || b == "-" || b <= 0) print "-"; else printf "%.3g", a / b }')" "$last_level" "$first_level"
    printf 'cold_start_first_pass\t%s\t<\t0.5\ts\tcold start to first pass (start-up probe, no shader cache)\n' \
        "$(value startup 13)"
    printf 'packed_bytes_per_triangle\t%s\t<=\t100\tB\tpacked bytes per triangle, mesh-%s\n' \
        "$(value "mesh-$last_level" 12)" "$last_level"
    # issue 14: importing a million triangles
    for label in gltf ply; do
        import_log=$(cat "$work/$label-1M-import.log" 2>/dev/null || true)
        printf '%s_1M_load_and_pack\t%s\t<\t3\ts\t%s-1M: load and pack, wall seconds (import_time; CPU %s s)\n' "$label" \
            "$(field "$import_log" 's/.*together \([0-9.]*\) s.*/\1/p')" "$label" \
            "$(field "$import_log" 's/.*(CPU \([0-9.]*\) s).*/\1/p')"
        printf '%s_1M_packed_bytes_per_triangle\t%s\t<=\t100\tB\tpacked bytes per triangle, %s-1M\n' "$label" \
            "$(value "$label-1M" 12)" "$label"
    done
    # issue 15: light groups and sweeps
    printf 'light_groups_time_per_sample_ratio\t%s\t<=\t1.1\tx\tlights.txt time per sample, --light-groups / none (median of %s pairs)\n' \
        "$(for suffix in "" $(seq 2 "$rounds" | sed 's/^/-/'); do echo "$(ratio "$(value "lights-groups$suffix" 10)" "$(value "lights$suffix" 10)")"; done |
            grep -v '^-$' | sort -g | awk '{ v[NR] = $1 } END { print NR == 0 ? "-" : v[int((NR + 1) / 2)] }')" "$rounds"
    printf 'sweep_saving_per_row_over_startup\t%s\t>=\t1\tx\t%s\n' \
        "$(awk -v s="$(value sweep-12 6)" -v p="$(value sweep-12-separate 6)" -v u="$(value startup-cached 13)" 'BEGIN {
            if (s == "-" || p == "-" || u == "-" || u <= 0) print "-"; else printf "%.3g", (p - s) / 11 / u }')" \
        "12-row sweep: (12 separate renders - the sweep) / 11 / a cached start-up's first pass"
    # issue 17: any image size in bounded memory
    printf 'panorama_20000x2000_peak_rss\t%s\t<\t1536\tMiB\tpanorama-20000 (1 spp, tiles): peak resident set\n' \
        "$(value panorama-20000 14)"
    printf 'square_16384_peak_rss\t%s\t<\t2048\tMiB\tsquare-16384 (1 spp, depth 2, tiles): peak resident set\n' \
        "$(value square-16384 14)"
    printf 'full_hd_rss_ratio\t%s\t<=\t1\tx\t1920x1080 peak resident set, default budget / never tiled\n' \
        "$(ratio "$(value full-hd 14)" "$(value full-hd-untiled 14)")"
    # issue 13, against Blender Cycles (tests/bench/peers.sh)
    printf 'weekend_time_ratio_cycles\t%s\t<=\t0.5\tx\tweekend at equal spp, render s rtspheres / Cycles\n' \
        "$(ratio "$(value weekend 7)" "$(value cycles-weekend 7)")"
    printf 'cornell_rmse_ratio_equal_time\t%s\t<=\t1\tx\tCornell RMSE at equal time (Cycles %s spp), rtspheres / Cycles\n' \
        "$(quality_value cornell rmse_ratio_equal_render_time)" "$quality_point"
    # "... with --noise-threshold better still": below the fixed spp ladder's ratio.
    fixed_ratio=$(quality_value cornell rmse_ratio_equal_render_time)
    adaptive_ratio=$(quality_value cornell adaptive_rmse_ratio_equal_render_time)
    [ "$fixed_ratio" != - ] || adaptive_ratio=-
    printf 'cornell_adaptive_rmse_ratio_equal_time\t%s\t<\t%s\tx\tCornell RMSE at equal time with --noise-threshold, rtspheres / Cycles (below the fixed spp ratio)\n' \
        "$adaptive_ratio" "$fixed_ratio"
    for label in cornell three-balls; do
        printf '%s_adaptive_time_ratio\t%s\t<=\t0.5\tx\t%s\n' "$(echo "$label" | tr - _)" \
            "$(quality_value "$label" adaptive_time_ratio)" \
            "$label: time for the RMSE of $quality_point spp, --noise-threshold / fixed spp"
    done
} | awk -F '\t' 'BEGIN { OFS = "\t" } {
    reached = ($3 == ">=" && $2 >= $4) || ($3 == "<=" && $2 <= $4) || ($3 == "<" && $2 < $4)
    met = $2 == "-" ? "unknown" : reached ? "met" : "missed"
    print $1, $2, $3, $4, $5, $6, met }' >"$targets"
echo
echo "targets (ratios measured in this run):"
awk -F '\t' '{ printf "  %-80s %7s %-2s %-3s %-2s %s\n", $6, $2, $3, $4, $5, $7 }' "$targets"
# Counting the set-up in (the one-off costs the growth target leaves to their own columns):
echo "  (time per sample with BVH build, packing, upload and compile in it: mesh-$last_level / mesh-$first_level = $(awk -F '\t' \
    -v a="mesh-$last_level" -v b="mesh-$first_level" '$1 == a || $1 == b {
        split($2, wh, "x"); t[$1] = $7 == "-" ? -1 : $7 / (wh[1] * wh[2] * $3) }
    END { if (t[a] > 0 && t[b] > 0) printf "%.3g", t[a] / t[b]; else print "unknown" }' "$rows"))"
# Other work on the machine takes cores from whichever renderer runs at the time: path
# segments per CPU-second (all threads) are less sensitive to that than per wall second.
echo "  (path segments per CPU-second instead: $(awk -v a="$(value weekend 9)" -v ar="$(value weekend 7)" \
    -v ac="$(value weekend 16)" -v b="$(value reference-weekend 9)" -v br="$(value reference-weekend 7)" \
    -v bc="$(value reference-weekend 16)" 'BEGIN {
        if (a == "-" || ar == "-" || ac == "-" || b == "-" || br == "-" || bc == "-" || ac <= 0 || bc <= 0 || b <= 0)
            print "unknown"
        else printf "rtspheres %.3g, reference %.3g, ratio %.3g", a * ar / ac, b * br / bc,
                    (a * ar / ac) / (b * br / bc) }'))"
# The same for the peers' targets: other work moves wall seconds more than CPU seconds.
echo "  (by whole-process CPU seconds instead: weekend rtspheres / Cycles" \
    "$(ratio "$(value weekend 16)" "$(value cycles-weekend 16)"), Cornell RMSE at equal CPU time" \
    "$(quality_value cornell rmse_ratio_equal_cpu_time), time for Cycles' RMSE" \
    "$(quality_value cornell time_ratio_equal_rmse_cpu))"
# The start-up rows count from the command's start in main; the dynamic loader's work before
# it (OpenImageIO's libraries, docs/performance.md "Ideas") is in the process's figure.
startup_from_process=$(field "$(grep "rtspheres: scene:" "$work/startup.log" 2>/dev/null | tail -n 1)" \
    "s/.* and \([0-9.]*\) s after the process's.*/\1/p")
echo "  (first pass with Mesa's shader cache: $(value startup-cached 13) s;" \
    "weekend's own, a full 1200x675 pass: $(value weekend 13) s;" \
    "the cold start from the process's start, its libraries' loading before main in it: $startup_from_process s)"
echo "load average at the end $load_end"

# ---- JSON of this run -----------------------------------------------------------------------
# Prints $1 as a JSON string.
json_string() { printf '"%s"' "$(printf '%s' "$1" | sed 's/\\/\\\\/g; s/"/\\"/g')"; }
{
    printf '{\n  "date": "%s",\n' "$run_id"
    printf '  "machine": {"cpu": %s, "cores": %s, "renderer": %s, "load_average_start": %s, "load_average_end": %s},\n' \
        "$(json_string "$cpu_model")" "$(echo "$cores" | sed 's/^-$/null/')" "$(json_string "$renderer")" \
        "$(json_string "$load_start")" "$(json_string "$load_end")"
    printf '  "knobs": {"BENCH_SPP": %s, "BENCH_REFERENCE_SPP": %s, "BENCH_SCALE": %s, "BENCH_MESH_LEVELS": %s, ' \
        "$weekend_spp" "$reference_spp" "$scale" "$(json_string "$mesh_levels")"
    printf '"BENCH_PEERS": %s, "quality_spp": %s, "quality_point": %s, "quality_reference_spp": %s, ' \
        "$(json_string "$peers")" "$(json_string "$quality_spp")" "$quality_point" "$quality_reference_spp"
    printf '"noise_thresholds": %s, "peer_threads": %s},\n' "$(json_string "$noise_thresholds")" "$peer_threads"
    printf '  "scenes": [\n'
    awk -F '\t' 'function number(v) { return v == "-" || v == "" ? "null" : v }
        { printf "%s    {\"name\": \"%s\", \"size\": \"%s\", \"spp\": %s, \"frames\": %s, \"triangles\": %s, " \
              "\"wall_seconds\": %s, \"render_seconds\": %s, \"samples_per_second\": %s, " \
              "\"segments_per_second\": %s, \"seconds_per_sample\": %s, \"bvh_build_seconds\": %s, " \
              "\"bytes_per_triangle\": %s, \"first_pass_seconds\": %s, \"peak_rss_mib\": %s, " \
              "\"frames_per_second\": %s, \"cpu_seconds\": %s, \"note\": \"%s\", \"renderer\": \"%s\", " \
              "\"rmse\": %s}", (NR > 1 ? ",\n" : ""), $1, $2,
              number($3), number($4), number($5), number($6), number($7), number($8), number($9), number($10),
              number($11), number($12), number($13), number($14), number($15), number($16), $17, $18, number($19) }
        END { print "" }' "$rows"
    printf '  ],\n'
    printf '  "weekend_mean": {"rtspheres": [%s], "reference": [%s], "largest_difference_percent": %s},\n' \
        "$(echo "${rtspheres_mean:-}" | sed 's/ /, /g')" "$(echo "${reference_mean:-}" | sed 's/ /, /g')" \
        "$(echo "$mean_difference" | sed 's/^-$/null/')"
    # Time to quality: per scene its facts; "R G B" means become arrays, "-" null.
    printf '  "quality": {'
    sort -s -t "$(printf '\t')" -k 1,1 "$quality" | awk -F '\t' 'function json(v) {
            if (v == "-" || v == "") return "null"
            if (v ~ /^-?[0-9.]+(e[+-]?[0-9]+)?$/) return v
            if (v ~ /^[0-9.e+-]+ [0-9.e+-]+ [0-9.e+-]+$/) { gsub(/ /, ", ", v); return "[" v "]" }
            gsub(/"/, "\\\"", v); return "\"" v "\"" }
        NF < 3 { next }
        $1 != label { printf "%s\n    \"%s\": {", label == "" ? "" : "},", $1; label = $1; n = 0 }
        { printf "%s\"%s\": %s", n++ ? ", " : "", $2, json($3) }
        END { print label == "" ? "}," : "}\n  }," }'
    printf '  "peer_notes": %s,\n' "$(json_string "$(printf '%s' "$peer_notes" | sed 's/^ *//' | tr '\n' ';')")"
    printf '  "targets": [\n'
    awk -F '\t' '{ printf "%s    {\"name\": \"%s\", \"value\": %s, \"comparison\": \"%s\", \"limit\": %s, " \
                      "\"unit\": \"%s\", \"what\": \"%s\", \"status\": \"%s\"}", (NR > 1 ? ",\n" : ""), $1,
                      $2 == "-" ? "null" : $2, $3, $4, $5, $6, $7 } END { print "" }' "$targets"
    printf '  ],\n  "chart": "%s"\n}\n' "$chart"
} >"$json"
echo "results: $json (this run), rows appended to $csv"
[ "$failures" = 0 ] || { echo "bench: $failures render(s) FAILED" >&2; exit 1; }
