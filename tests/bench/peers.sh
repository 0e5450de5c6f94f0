# peers.sh: the rows of `make bench` that measure rtspheres against the renderers a user
# would pick instead (issue 13, part 5): Blender Cycles for path tracing, POV-Ray for the
# Whitted frame. Sourced by tests/bench/run.sh after its measuring functions (it uses
# build_tool, bench, record, field, scaled, value and run.sh's variables work, program,
# rows, scale, failures); it only defines functions and variables, run.sh calls them.
#
# The peers come from Debian (.ci/bench-packages, installed by `make bench` when
# missing, never by the tests): `blender` (3.4.1, Cycles) and `povray` (3.7). A peer that
# is not installed has its rows skipped with a note; the rest of the bench runs as before.
#
# The scenes are rebuilt for each peer by scripts that read the rtspheres scene files with
# tests/bench/scene_reader.py, a reader of their own (a yardstick shares no code with
# what it measures): tests/bench/cycles/render.py (Blender's Python) and
# tests/bench/povray_scene.py.
#
# Time to quality (quality_scene): for each renderer a ladder of spp, each render's time
# and its RMSE (tests/bench/image_error.cpp: over all pixels and R, G, B) against that
# renderer's own high-spp reference, so that the RMSE measures noise and not the small
# differences between the two renderers' material models (both references' mean colours
# are printed, so that a mismatch of scenes shows). The ladder renders with seed 1, the
# references with seed 2 (independent noise). A reference is rendered once and cached in
# build/bench/quality/, named by a hash of the scene file, the settings and (for Cycles)
# the scripts that build it, so a changed scene or script renders a new one; rtspheres'
# own changes do not (it is a converged image, which an unbiased change leaves alone):
# BENCH_QUALITY_REFRESH=1 renders them again. A reference holds noise of its own,
# 1 / (reference spp) of a sample's variance, which adds to every RMSE: at the default
# 2048 spp that inflates an RMSE at 256 spp by about 6% and at 64 spp by 1.5%.
#
# Knobs (environment; BENCH_SCALE multiplies every spp here as it does elsewhere):
#   BENCH_PEERS                  peers to run (default "cycles povray"; "" for none)
#   BENCH_QUALITY_SPP            the ladder (default "8 16 32 64 128 256")
#   BENCH_QUALITY_POINT          the spp whose Cycles RMSE and time are the comparison's
#                                point (default 64)
#   BENCH_QUALITY_REFERENCE_SPP  the references' spp (default 2048)
#   BENCH_QUALITY_REFRESH        1: render the references again
#   BENCH_NOISE_THRESHOLDS       the adaptive ladder of --noise-threshold values (default
#                                "0.4 0.3 0.2 0.15 0.1 0.05 0.025", at most 1024 spp
#                                each: the steps near 64 spp's RMSE (T 0.15 to 0.2) are what
#                                the interpolation of the adaptive target reads), run
#                                only when `rtspheres render --help` lists the option
#   BENCH_QUALITY_DENOISE_SPP    the --denoise ladder (default "4 8 16 32 64"): rtspheres'
#                                time by wall s (the denoiser runs after the passes, which
#                                render s leaves out) to its own RMSE at BENCH_QUALITY_POINT
#                                fixed spp, against the fixed render's wall s
#   BENCH_PEER_THREADS           threads of Cycles and POV-Ray (default: the cores,
#                                as llvmpipe uses)
# shellcheck shell=sh disable=SC2154 # work, program, rows, CXX ...: run.sh's variables

peers=${BENCH_PEERS-cycles povray}
quality_spp=$(for s in ${BENCH_QUALITY_SPP:-8 16 32 64 128 256}; do scaled "$s"; done | sort -n -u | tr '\n' ' ' | sed 's/ $//')
quality_point=$(scaled "${BENCH_QUALITY_POINT:-64}")
quality_reference_spp=$(scaled "${BENCH_QUALITY_REFERENCE_SPP:-2048}")
noise_thresholds=${BENCH_NOISE_THRESHOLDS:-0.4 0.3 0.2 0.15 0.1 0.05 0.025}
adaptive_max_spp=$(scaled 1024)
denoise_spp=$(for s in ${BENCH_QUALITY_DENOISE_SPP:-4 8 16 32 64}; do scaled "$s"; done | sort -n -u | tr '\n' ' ' | sed 's/ $//')
peer_threads=${BENCH_PEER_THREADS:-$(nproc 2>/dev/null || echo 2)}
quality=$work/quality.tsv      # this run's time-to-quality results: label, key, value
quality_reference=             # set while a ladder runs: image_rmse's reference
peer_notes=                    # why peer rows were skipped, for the summary
: >"$quality"

# Succeeds when peer NAME (cycles or povray) is asked for and its program is there;
# otherwise fails and adds the reason to the notes (once), which the summary prints.
peer_ready() {
    case $1 in cycles) command=blender ;; *) command=povray ;; esac
    case " $peers " in
        *" $1 "*) command -v "$command" >/dev/null 2>&1 && return 0
                  reason="'$command' is not installed (make bench installs .ci/bench-packages)" ;;
        *) reason="not in BENCH_PEERS" ;;
    esac
    case $peer_notes in *"$1 rows skipped"*) ;; *)
        echo "  $1 rows skipped: $reason"
        peer_notes="${peer_notes}  $1 rows skipped: $reason
" ;;
    esac
    return 1
}

# shellcheck disable=SC2046 # pkg-config prints several flags, to be split into words
build_tool "$work/image_error" tests/bench/image_error.cpp \
    "$CXX" -std=c++17 -Wall -Wextra -O2 $(pkg-config --cflags OpenImageIO) tests/bench/image_error.cpp \
    $(pkg-config --libs OpenImageIO) -o "$work/image_error"

# Prints the RMSE of image $1 against $quality_reference, or "-" when there is none.
image_rmse() {
    if [ -z "$quality_reference" ] || [ ! -f "$quality_reference" ] || [ ! -f "$1" ]; then
        echo -
        return 0
    fi
    found=$("$work/image_error" "$1" "$quality_reference" 2>/dev/null | sed -n 's/.* rmse \([0-9.e+-]*\) .*/\1/p')
    echo "${found:--}"
}

# Runs tests/bench/cycles/render.py in Blender under the peak-RSS wrapper with the
# arguments given (SCENE -o OUT ...) and the peers' thread count.
run_cycles() {
    "$work/peak_rss" blender -b --factory-startup -noaudio --python-exit-code 1 -P tests/bench/cycles/render.py \
        -- "$@" --threads "$peer_threads"
}

# Renders SCENE in Cycles as NAME (SIZE, SPP; the arguments after NOTE go to
# tests/bench/cycles/render.py, e.g. --max-depth 50) and records its row: render s is
# Cycles' render call, wall s the whole Blender process (its start-up included).
bench_cycles() {
    name=$1 scene=$2 size=$3 spp=$4 note=$5
    shift 5
    out="$work/$name.exr" log="$work/$name.log"
    rm -f "$out"
    if ! run_cycles "$scene" -o "$out" --size "$size" --spp "$spp" "$@" >"$log" 2>&1 || [ ! -f "$out" ]; then
        echo "$name: Cycles FAILED (see $log:)"; grep -v '^Fra:' "$log" | tail -n 3
        failures=$((failures + 1))
        return 0
    fi
    summary=$(grep '^cycles:' "$log" | tail -n 1)
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    render_seconds=$(field "$summary" 's/.* spp in \([0-9.]*\) s (render call).*/\1/p')
    rates=$(awk -v s="$render_seconds" -v size="$size" -v spp="$spp" 'BEGIN {
        split(size, wh, "x"); n = wh[1] * wh[2] * spp
        if (s == "-" || s <= 0) print "- -"; else printf "%.3g %.4g\n", n / s, s / n }')
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    rss=$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')
    rmse=$(image_rmse "$out")
    [ "$rmse" = - ] || note="${note:+$note; }RMSE $rmse"
    record "$name" "$size" "$spp" 1 - "$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')" "$render_seconds" \
        "${rates% *}" - "${rates#* }" - - - "$rss" - "$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')" \
        "Cycles, render call (Blender start-up in wall s)${note:+; $note}" cycles "$rmse"
}

# Sets reference_image to RENDERER's (rtspheres or cycles) reference of SCENE (LABEL) at
# SIZE and DEPTH, rendering it first unless a cached one matches; empty when it failed.
quality_reference() {
    reference_renderer=$1 label=$2 scene=$3 size=$4 depth=$5
    settings="$reference_renderer $size spp $quality_reference_spp depth $depth seed 2"
    key=$( { cat "$scene"; echo "$settings"
             [ "$reference_renderer" = rtspheres ] || cat tests/bench/cycles/render.py tests/bench/scene_reader.py; } |
          sha256sum | cut -c 1-16)
    reference_image="$work/quality/$reference_renderer-$label-$key.exr"
    mkdir -p "$work/quality"
    if [ -f "$reference_image" ] && [ "${BENCH_QUALITY_REFRESH:-0}" != 1 ]; then
        echo "  $reference_renderer reference of $label: cached ($reference_image, $settings)"
        return 0
    fi
    partial="$work/quality/$reference_renderer-$label-$key.partial.exr" log="$work/quality/$reference_renderer-$label-$key.log"
    echo "  $reference_renderer reference of $label: rendering $settings (once; cached in $work/quality/)"
    status=0
    if [ "$reference_renderer" = rtspheres ]; then
        "$work/peak_rss" "$program" render "$scene" -o "$partial" --size "$size" --spp "$quality_reference_spp" \
            --max-depth "$depth" --seed 2 --quiet >"$log" 2>&1 || status=$?
    else
        run_cycles "$scene" -o "$partial" --size "$size" --spp "$quality_reference_spp" --max-depth "$depth" \
            --seed 2 >"$log" 2>&1 || status=$?
    fi
    if [ "$status" = 0 ] && [ -f "$partial" ]; then
        mv "$partial" "$reference_image"
        echo "  ... done: $(grep '^peak_rss:' "$log" | tail -n 1)"
    else
        echo "  $reference_renderer reference of $label FAILED (see $log); its RMSE columns stay empty"
        grep -v '^Fra:' "$log" | tail -n 3
        reference_image=
        failures=$((failures + 1))
    fi
}

# Prints y at x = $1 on the log-log polyline through the points "x y" on stdin (in any
# order), extrapolated along the end segments; "-" with fewer than two usable points.
loglog_at() {
    sort -g | awk -v at="$1" '$1 > 0 && $2 > 0 { n++; x[n] = log($1); y[n] = log($2) }
        END {
            if (n < 2 || at == "-" || at <= 0) { print "-"; exit }
            t = log(at); i = 1
            while (i < n - 1 && t > x[i + 1]) i++
            if (x[i + 1] == x[i]) { print "-"; exit }
            printf "%.4g\n", exp(y[i] + (t - x[i]) * (y[i + 1] - y[i]) / (x[i + 1] - x[i])) }'
}

# Prints "TIME RMSE" of this run's ladder rows named PREFIX then a number of spp (column
# $2 the time: 7 render s, 6 wall s, 16 CPU s), one point a line.
ladder_points() {
    awk -F '\t' -v prefix="$1" -v column="$2" 'index($1, prefix) == 1 && substr($1, length(prefix) + 1) ~ /^[0-9]+$/ &&
        $column != "-" && $19 != "-" { print $column, $19 }' "$rows"
}

# Adds "LABEL KEY VALUE" to this run's quality results.
quality_fact() { printf '%s\t%s\t%s\n' "$1" "$2" "$3" >>"$quality"; }

# Prints a / b with 3 significant digits, or "-".
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a == "-" || b == "-" || b <= 0) print "-"; else printf "%.3g", a / b }'; }

# Time to quality on SCENE (LABEL) at SIZE and DEPTH: the references, the ladders of
# rtspheres and Cycles (rows LABEL@SPP and cycles:LABEL@SPP), the adaptive ladder
# (LABEL@ntT) when rtspheres has --noise-threshold, with more rounds (BENCH_ROUNDS in all) of
# its rungs around the fixed ladder's RMSE (LABEL@rNntT, LABEL@SPP-rN), and the comparison at Cycles'
# $quality_point spp (quality_compare).
quality_scene() {
    label=$1 scene=$2 size=$3 depth=$4
    echo "time to quality, $label ($size, depth $depth; ladder $quality_spp spp, references $quality_reference_spp spp):"
    quality_reference rtspheres "$label" "$scene" "$size" "$depth"
    quality_reference=$reference_image
    rtspheres_reference=$reference_image
    for spp in $quality_spp; do
        bench "$label@$spp" "$scene" "$size" "$spp" "" --max-depth "$depth" --seed 1
    done
    for spp in $denoise_spp; do
        bench "$label@dn$spp" "$scene" "$size" "$spp" "denoised" --max-depth "$depth" --seed 1 --denoise
    done
    if "$program" render --help 2>&1 | grep -q -- '--noise-threshold'; then
        for threshold in $noise_thresholds; do
            bench "$label@nt$threshold" "$scene" "$size" "$adaptive_max_spp" "adaptive" --max-depth "$depth" \
                --seed 1 --noise-threshold "$threshold"
        done
        quality_fact "$label" adaptive yes
        # More rounds of the fixed $quality_point-spp render and of the two adaptive rungs
        # around its RMSE (rows LABEL@SPP-rN, LABEL@rNntT; $rounds rounds in all with the
        # ladder's, BENCH_ROUNDS in run.sh): the ratio of such 1-2 s renders moved by 10%
        # between runs of one binary and by 0.405-0.533 within one run (docs/performance.md),
        # so the target takes the median of the rounds' ratios (quality_compare). The
        # images are the same in every round (same seed; adaptive decisions do not depend
        # on the passes), only the times differ.
        point_rmse=$(value "$label@$quality_point" 19)
        bracket=$(awk -F '\t' -v prefix="$label@nt" 'index($1, prefix) == 1 && $19 != "-" {
            print substr($1, length(prefix) + 1), $19 }' "$rows" | sort -g -k 2 | awk -v r="$point_rmse" '
            r == "-" { exit } $2 <= r { below = $1 } $2 > r && above == "" { above = $1 }
            END { if (below != "" && above != "") print below, above }')
        for round in $(seq 2 "$rounds"); do
            [ -n "$bracket" ] || break
            bench "$label@$quality_point-r$round" "$scene" "$size" "$quality_point" "round $round" \
                --max-depth "$depth" --seed 1
            for threshold in $bracket; do
                bench "$label@r${round}nt$threshold" "$scene" "$size" "$adaptive_max_spp" "adaptive, round $round" \
                    --max-depth "$depth" --seed 1 --noise-threshold "$threshold"
            done
        done
    else
        echo "  adaptive rows skipped: this rtspheres has no --noise-threshold (rtspheres render --help)"
        quality_fact "$label" adaptive "skipped: no --noise-threshold in rtspheres render --help"
    fi
    cycles_reference=
    if peer_ready cycles; then
        quality_reference cycles "$label" "$scene" "$size" "$depth"
        quality_reference=$reference_image
        cycles_reference=$reference_image
        for spp in $quality_spp; do
            bench_cycles "cycles:$label@$spp" "$scene" "$size" "$spp" "" --max-depth "$depth" --seed 1
        done
    fi
    quality_reference=
    for image in "rtspheres $rtspheres_reference" "cycles $cycles_reference"; do
        if [ -n "${image#* }" ]; then
            quality_fact "$label" "${image%% *}_reference_mean" \
                "$("$work/image_error" "${image#* }" 2>/dev/null | sed -n 's/^mean //p')"
        fi
    done
}

# Compares the ladders of LABEL (quality_scene) and prints and records the results:
# Cycles' RMSE and time at $quality_point spp; rtspheres' RMSE at that time and the time
# it needs for that RMSE (log-log interpolation between its ladder points), as ratios to
# Cycles' (by render s, wall s and CPU s); the adaptive ladder's time for rtspheres' own
# RMSE at $quality_point spp.
quality_compare() {
    label=$1
    means=$(awk -F '\t' -v l="$label" '$1 == l && $2 ~ /_reference_mean$/ { sub(/_reference_mean/, "", $2)
        printf "%s%s %s", n++ ? ", " : "", $2, $3 }' "$quality")
    reference_difference=$(awk -F '\t' -v l="$label" '$1 == l && $2 ~ /_reference_mean$/ { m[++n] = $3 }
        END { if (n < 2) { print "-"; exit }
              split(m[1], a, " "); split(m[2], b, " ")
              for (i = 1; i <= 3; i++) { d = (a[i] - b[i]) / (b[i] > 0 ? b[i] : 1); d = d < 0 ? -d : d; if (d > w) w = d }
              printf "%.2g", 100 * w }' "$quality")
    quality_fact "$label" reference_mean_difference_percent "$reference_difference"
    echo "  $label references' mean colours: ${means:-none} (largest difference ${reference_difference}%)"
    own_rmse=$(value "$label@$quality_point" 19) own_time=$(value "$label@$quality_point" 7)
    quality_fact "$label" rtspheres_point_seconds "$own_time"
    quality_fact "$label" rtspheres_point_rmse "$own_rmse"
    if [ "$(value "cycles:$label@$quality_point" 7)" != - ]; then
        quality_fact "$label" cycles_point_rmse "$(value "cycles:$label@$quality_point" 19)"
        # render s (the headline), whole-process wall s, and whole-process CPU s (all threads,
        # start-up in it): the last is the least moved by other work on the machine.
        for column in 7 6 16; do
            case $column in 7) what=render ;; 6) what=wall ;; *) what=cpu ;; esac
            cycles_time=$(value "cycles:$label@$quality_point" "$column")
            cycles_rmse=$(value "cycles:$label@$quality_point" 19)
            at_time=$(ladder_points "$label@" "$column" | loglog_at "$cycles_time")
            for_rmse=$(ladder_points "$label@" "$column" | awk '{ print $2, $1 }' | loglog_at "$cycles_rmse")
            quality_fact "$label" "cycles_point_${what}_seconds" "$cycles_time"
            quality_fact "$label" "rtspheres_rmse_at_cycles_${what}_time" "$at_time"
            quality_fact "$label" "rmse_ratio_equal_${what}_time" "$(ratio "$at_time" "$cycles_rmse")"
            quality_fact "$label" "rtspheres_${what}_seconds_for_cycles_rmse" "$for_rmse"
            quality_fact "$label" "time_ratio_equal_rmse_${what}" "$(ratio "$for_rmse" "$cycles_time")"
            echo "  $label, $what s: Cycles $quality_point spp ${cycles_time} s, RMSE $cycles_rmse;" \
                "rtspheres at that time RMSE $at_time ($(ratio "$at_time" "$cycles_rmse")x), for that RMSE" \
                "$for_rmse s ($(ratio "$for_rmse" "$cycles_time")x)"
        done
        # The issue's "with --noise-threshold better still": the adaptive ladder's RMSE at
        # Cycles' render time (log-log between its thresholds' points, as above).
        cycles_time=$(value "cycles:$label@$quality_point" 7)
        cycles_rmse=$(value "cycles:$label@$quality_point" 19)
        adaptive_at_time=$(awk -F '\t' -v prefix="$label@nt" 'index($1, prefix) == 1 && $7 != "-" && $19 != "-" {
            print $7, $19 }' "$rows" | loglog_at "$cycles_time")
        quality_fact "$label" adaptive_rmse_at_cycles_render_time "$adaptive_at_time"
        quality_fact "$label" adaptive_rmse_ratio_equal_render_time "$(ratio "$adaptive_at_time" "$cycles_rmse")"
        echo "  $label with --noise-threshold, render s: at Cycles' $quality_point-spp time RMSE $adaptive_at_time" \
            "($(ratio "$adaptive_at_time" "$cycles_rmse")x Cycles')"
    fi
    adaptive_time=$(awk -F '\t' -v prefix="$label@nt" 'index($1, prefix) == 1 && $7 != "-" && $19 != "-" {
        print $19, $7 }' "$rows" | loglog_at "$own_rmse")
    quality_fact "$label" adaptive_seconds_for_point_rmse "$adaptive_time"
    # The adaptive target: the median of the rounds' ratios (quality_scene's rounds 2 and on
    # time the fixed render and the two rungs around its RMSE again).
    adaptive_ratios=$(ratio "$adaptive_time" "$own_time")
    for round in $(seq 2 "$rounds"); do
        round_time=$(awk -F '\t' -v prefix="$label@r${round}nt" 'index($1, prefix) == 1 && $7 != "-" && $19 != "-" {
            print $19, $7 }' "$rows" | loglog_at "$own_rmse")
        adaptive_ratios="$adaptive_ratios $(ratio "$round_time" "$(value "$label@$quality_point-r$round" 7)")"
    done
    adaptive_median=$(echo "$adaptive_ratios" | tr ' ' '\n' | grep -v '^-*$' | sort -g |
        awk '{ v[NR] = $1 } END { print NR == 0 ? "-" : v[int((NR + 1) / 2)] }')
    quality_fact "$label" adaptive_time_ratio "$adaptive_median"
    quality_fact "$label" adaptive_time_ratio_rounds "$adaptive_ratios"
    echo "  $label with --noise-threshold, render s: the RMSE of $quality_point fixed spp in" \
        "${adaptive_time} s against ${own_time} s; time ratio by round $adaptive_ratios (median $adaptive_median)"
    # --denoise against the same renders undenoised, by wall s (the denoiser is not in
    # render s): the RMSE at the fixed ladder's $quality_point-spp time, and the time for
    # its RMSE (extrapolated past the ladder's end when the denoised images never reach it).
    own_wall=$(value "$label@$quality_point" 6)
    denoised_at_time=$(ladder_points "$label@dn" 6 | loglog_at "$own_wall")
    denoised_time=$(ladder_points "$label@dn" 6 | awk '{ print $2, $1 }' | loglog_at "$own_rmse")
    quality_fact "$label" denoised_rmse_at_point_wall_time "$denoised_at_time"
    quality_fact "$label" denoised_rmse_ratio_equal_wall_time "$(ratio "$denoised_at_time" "$own_rmse")"
    quality_fact "$label" denoised_wall_seconds_for_point_rmse "$denoised_time"
    quality_fact "$label" denoised_time_ratio_wall "$(ratio "$denoised_time" "$own_wall")"
    echo "  $label with --denoise, wall s: rtspheres $quality_point spp ${own_wall} s, RMSE $own_rmse; denoised at" \
        "that time RMSE $denoised_at_time ($(ratio "$denoised_at_time" "$own_rmse")x), for that RMSE" \
        "$denoised_time s ($(ratio "$denoised_time" "$own_wall")x)"
}

# Renders SCENE (spheres only) in POV-Ray as NAME at SIZE, the counterpart of rtspheres'
# Whitted frame: the scene written by tests/bench/povray_scene.py (an 8x8 area light for
# the light sphere), trace depth DEPTH, 2x2 supersampling of every pixel (+A0.0 +AM1
# +R2: about 4 samples a pixel, as rtspheres' 4 spp). render s is POV-Ray's own trace
# time (parsing, a few ms here, apart), wall s the whole process.
bench_povray() {
    name=$1 scene=$2 size=$3 depth=$4
    log="$work/$name.log"
    rm -f "$work/$name.png"
    if ! python3 tests/bench/povray_scene.py "$scene" "$work/$name.pov" >"$log" 2>&1 ||
        ! "$work/peak_rss" povray +I"$work/$name.pov" +O"$work/$name.png" +FN +W"${size%x*}" +H"${size#*x}" -D \
            +WT"$peer_threads" +A0.0 +AM1 +R2 >>"$log" 2>&1 || [ ! -f "$work/$name.png" ]; then
        echo "$name: POV-Ray FAILED (see $log:)"; tr '\r' '\n' <"$log" | grep -v '^Rendered' | tail -n 3
        failures=$((failures + 1))
        return 0
    fi
    stats=$(tr '\r' '\n' <"$log" | grep -v '^Rendered')
    trace=$(field "$stats" 's/.*Trace Time:.*(\([0-9.]*\) seconds).*/\1/p')
    samples=$(field "$stats" 's/.*Samples: *\([0-9]*\) .*/\1/p')
    per_pixel=$(field "$stats" 's/.*Smpls\/Pxl: *\([0-9.]*\).*/\1/p')
    rates=$(awk -v s="$trace" -v n="$samples" 'BEGIN {
        if (s == "-" || n == "-" || s <= 0) print "- -"; else printf "%.3g %.4g\n", n / s, s / n }')
    measured=$(grep "^peak_rss:" "$log" | tail -n 1)
    rss=$(field "$measured" 's/^peak_rss: \([0-9]*\) KiB.*/\1/p')
    rss=$(awk -v k="$rss" 'BEGIN { if (k == "-") print "-"; else printf "%.0f", k / 1024 }')
    record "$name" "$size" 4 1 - "$(field "$measured" 's/.*, \([0-9.]*\) s wall.*/\1/p')" "$trace" "${rates% *}" - \
        "${rates#* }" - - - "$rss" - "$(field "$measured" 's/.*, \([0-9.]*\) s CPU.*/\1/p')" \
        "POV-Ray, trace time; Whitted, 8x8 area light, $per_pixel samples/pixel" povray -
}
