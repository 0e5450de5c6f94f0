#!/bin/sh
# test-farm.sh: what render farms need of `rtspheres render` (issue 17, "Logs, statistics
# and reruns"): progress lines in a log (stderr a file), none with --quiet, no carriage
# return; --stats-json parses and holds the values of a known render (sizes, spp, passes,
# stop reason, samples matching the EXR's samples channel); --threads 1 runs one llvmpipe
# thread (counted by the device, as `info` shows it); --skip-existing skips complete
# frames, resumes a partial one to the uninterrupted image and renders again one made from
# another scene or with other options. Tiny images: every render here takes well under a
# second on llvmpipe.
#   usage: sh tests/render/test-farm.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
scene=scenes/three-balls.txt
render_options="--size 32x18 --spp 16 --seed 5"

# json FILE EXPRESSION: prints EXPRESSION (Python, over the parsed document `d`) or
# "error: ..." when the file does not parse.
json() {
    python3 -c 'import json, sys
try:
    d = json.load(open(sys.argv[1]))
except Exception as e:
    print("error: %s" % e); sys.exit(0)
print(eval(sys.argv[2]))' "$1" "$2" 2>&1
}
if ! command -v python3 >/dev/null 2>&1; then
    echo "SKIP stats-json checks: python3 is missing"
fi

# ---- progress lines and --stats-json of one known render --------------------------------
"$program" render "$scene" -o "$scratch/known.exr" $render_options --progress-interval 0 \
    --stats-json "$scratch/known.json" 2>"$scratch/known.log"
lines=$(grep -c "^rtspheres: progress [0-9.]*%, [0-9]* of 9216 samples, [0-9.]* s elapsed, ETA [0-9.]* s, pass [0-9]*$" \
    "$scratch/known.log")
if [ "$lines" -ge 1 ] && [ "$(tr -cd '\r' <"$scratch/known.log" | wc -c)" = 0 ] &&
   grep -q "progress 100.0%, 9216 of 9216 samples" "$scratch/known.log" && grep -q "32x18, 16 spp in" "$scratch/known.log"; then
    pass "stderr a file: progress lines (samples, %, elapsed, ETA), no carriage return, then the summary"
else
    fail "progress lines in a log" "$(head -c 400 "$scratch/known.log")"
fi
if command -v python3 >/dev/null 2>&1; then
    stats_of "$scratch/known.exr"
    channel_samples=$(awk -v m="$(stat_mean samples)" 'BEGIN { printf "%.0f", m * 32 * 18 }')
    got=$(json "$scratch/known.json" '"%s %d %s %d %d %d %d %s %d %d %d %d %s" % (d["schema"], d["version"], i["outcome"], i["width"], i["height"], i["spp"], i["samples"], i["stop_reason"], i["spp_per_pixel"]["min"], i["spp_per_pixel"]["max"], len(d["images"]), i["scene"]["lights"], i["scene"]["light_choice"]) if (i := d["images"][0]) else ""')
    expected="rtspheres-render-stats 1 rendered 32 18 16 9216 spp 16 16 1 1 one"
    if [ "$got" = "$expected" ] && [ "$channel_samples" = 9216 ]; then
        pass "stats JSON holds the known render: 32x18, 16 spp, 9216 samples (the samples channel's sum), stop reason spp, one light"
    else
        fail "stats JSON of a known render" "got '$got', expected '$expected'; samples channel sum $channel_samples"
    fi
    # One progress line per pass with --progress-interval 0: the JSON's pass count.
    passes=$(json "$scratch/known.json" 'd["images"][0]["passes"]')
    hashes=$(json "$scratch/known.json" 'd["images"][0]["scene_hash"] + " " + d["images"][0]["options_hash"]')
    if [ "$passes" = "$lines" ] && [ "$hashes" = "$(stat_metadata scene_hash) $(stat_metadata options_hash)" ]; then
        pass "stats JSON: $passes passes (one progress line each), the EXR's scene and options hashes"
    else
        fail "stats JSON passes and hashes" "passes '$passes', progress lines $lines; hashes '$hashes' vs the EXR's"
    fi
    times=$(json "$scratch/known.json" 'all(isinstance(v, (int, float)) and v >= 0 for v in d["images"][0]["seconds"].values()) and d["images"][0]["seconds"]["compile"] <= d["images"][0]["seconds"]["first_pass"] <= d["images"][0]["seconds"]["total"] and d["images"][0]["seconds"]["first_pass_after_command_start"] < d["images"][0]["seconds"]["first_pass_after_process_start"] < d["images"][0]["seconds"]["first_pass_after_command_start"] + 60 and d["images"][0]["peak_rss_bytes"] > 0 and d["images"][0]["scene"]["packed_bytes"] > 0 and d["summary"]["finished"] and d["summary"]["rendered"] == 1')
    if [ "$times" = True ]; then pass "stats JSON: timings ordered (compile <= first pass <= total; the first pass later after the process's start than after the command's, by less than a minute), peak RSS, packed bytes, summary"
    else fail "stats JSON timings and summary" "$times: $(head -c 600 "$scratch/known.json")"; fi
fi

# ---- --quiet and --progress none ------------------------------------------------------------
"$program" render "$scene" -o "$scratch/quiet.exr" $render_options --progress-interval 0 --quiet 2>"$scratch/quiet.log"
if [ ! -s "$scratch/quiet.log" ]; then pass "--quiet: no progress lines, nothing at all"
else fail "--quiet prints nothing" "$(head -c 300 "$scratch/quiet.log")"; fi
"$program" render "$scene" -o "$scratch/none.exr" $render_options --progress none --progress-interval 0 2>"$scratch/none.log"
if ! grep -q "progress" "$scratch/none.log" && [ "$(wc -l <"$scratch/none.log")" = 1 ]; then
    pass "--progress none: the summary line only"
else
    fail "--progress none" "$(head -c 300 "$scratch/none.log")"
fi

# ---- adaptive sampling: the noise level in the lines, per-pixel spp in the JSON ----------
"$program" render "$scene" -o "$scratch/adaptive.exr" --size 32x18 --spp 256 --noise-threshold 0.2 --min-spp 8 \
    --progress lines --progress-interval 0 --stats-json "$scratch/adaptive.json" 2>"$scratch/adaptive.log"
if grep -q "; noise: [0-9.]*% of pixels at or above 0.2 (mean error [0-9.e-]*), [0-9]* still sampling$" "$scratch/adaptive.log"; then
    pass "--noise-threshold: progress lines carry the noise level"
else
    fail "progress lines with the noise level" "$(head -c 400 "$scratch/adaptive.log")"
fi
if command -v python3 >/dev/null 2>&1; then
    stats_of "$scratch/adaptive.exr"
    channel_samples=$(awk -v m="$(stat_mean samples)" 'BEGIN { printf "%.0f", m * 32 * 18 }')
    range=$(stat_range samples)
    got=$(json "$scratch/adaptive.json" '"%s %d %d %d" % (i["stop_reason"], i["samples"], i["spp_per_pixel"]["min"], i["spp_per_pixel"]["max"]) if (i := d["images"][0]) else ""')
    if [ "$got" = "noise $channel_samples $range" ] && [ "${range% *}" != "${range#* }" ]; then
        pass "stats JSON of an adaptive render: stop reason noise, samples and per-pixel min/max as the EXR's ($got)"
    else
        fail "stats JSON of an adaptive render" "got '$got', EXR samples $channel_samples, range '$range'"
    fi
fi

# ---- --threads -------------------------------------------------------------------------------
if "$program" info | grep -q "^CPU threads: .*llvmpipe"; then
    one=$("$program" info --threads 1 | sed -n 's/^CPU threads: *\([0-9]*\) llvmpipe.*/\1/p')
    default=$("$program" info | sed -n 's/^CPU threads: *\([0-9]*\) llvmpipe.*/\1/p')
    cpus=$(nproc)
    if [ "$one" = 1 ] && [ "$default" -ge 1 ] && [ "$default" -le "$cpus" ]; then
        pass "info: --threads 1 runs 1 llvmpipe thread (default $default on $cpus CPUs)"
    else
        fail "info --threads 1" "with it '$one' threads, without '$default', $cpus CPUs"
    fi
    if command -v python3 >/dev/null 2>&1; then
        "$program" render "$scene" -o "$scratch/threads.exr" $render_options --threads 1 --quiet \
            --stats-json "$scratch/threads.json"
        got=$(json "$scratch/threads.json" '"%d %d" % (d["device"]["threads"], d["device"]["threads_requested"])')
        if [ "$got" = "1 1" ]; then pass "render --threads 1: the device ran 1 thread (stats JSON)"
        else fail "render --threads 1" "device threads, requested: '$got'"; fi
    fi
    # The environment is the caller's again once the context exists (children see it).
    if [ "$(LP_NUM_THREADS=2 "$program" info --threads 1 | sed -n 's/^CPU threads: *\([0-9]*\) .*/\1/p')" = 1 ]; then
        pass "--threads wins over LP_NUM_THREADS"
    else fail "--threads wins over LP_NUM_THREADS" "$("$program" info --threads 1 | grep threads)"; fi
else
    echo "SKIP --threads: the device is not llvmpipe (a GPU: --threads does nothing there)"
fi

# ---- bad values -----------------------------------------------------------------------------
expect_exit "--threads 0 is refused" 2 "--threads wants a whole number" \
    "$program" render "$scene" -o "$scratch/x.exr" --threads 0
expect_exit "--progress with a wrong word is refused" 2 "--progress wants auto, bar, lines or none" \
    "$program" render "$scene" -o "$scratch/x.exr" --progress sometimes
expect_exit "a negative --progress-interval is refused" 2 "--progress-interval wants a number of seconds" \
    "$program" render "$scene" -o "$scratch/x.exr" --progress-interval -1
expect_exit "--stats-json in a missing directory is refused before rendering" 2 "--stats-json: cannot create" \
    "$program" render "$scene" -o "$scratch/x.exr" --stats-json "$scratch/no/such/dir/s.json"
expect_exit "--skip-existing with --resume is refused" 2 "--skip-existing .* not with --resume" \
    "$program" render "$scene" -o "$scratch/x.exr" --skip-existing --resume "$scratch/known.exr"

# ---- --skip-existing -------------------------------------------------------------------------
frames="--size 32x18 --spp 8 --seed 5"
mkdir -p "$scratch/frames"
"$program" render "$scene" -o "$scratch/frames/f-%d.exr" --frames 0-1 $frames --quiet
cksum "$scratch"/frames/f-*.exr >"$scratch/sums.before"
"$program" render "$scene" -o "$scratch/frames/f-%d.exr" --frames 0-2 $frames --skip-existing \
    --stats-json "$scratch/skip.json" 2>"$scratch/skip.log"
cksum "$scratch"/frames/f-0.exr "$scratch"/frames/f-1.exr >"$scratch/sums.after"
if grep -q "^rtspheres: frame 0: skipped: .*f-0.exr is complete .* same scene and options" "$scratch/skip.log" &&
   grep -q "^rtspheres: frame 1: skipped: " "$scratch/skip.log" && ! grep -q "frame 2: skipped" "$scratch/skip.log" &&
   cmp -s "$scratch/sums.before" "$scratch/sums.after" && [ -f "$scratch/frames/f-2.exr" ]; then
    pass "--skip-existing: complete frames 0 and 1 are skipped (files untouched, said why), frame 2 rendered"
else
    fail "--skip-existing skips complete frames" "$(head -c 600 "$scratch/skip.log")"
fi
if command -v python3 >/dev/null 2>&1; then
    got=$(json "$scratch/skip.json" '" ".join("%d:%s" % (i["frame"], i["outcome"]) for i in d["images"])')
    if [ "$got" = "0:skipped 1:skipped 2:rendered" ]; then pass "stats JSON lists the skipped frames ($got)"
    else fail "stats JSON of skipped frames" "got '$got'"; fi
fi
# Another scene (a light moved by -D), and other options: rendered again, said why.
"$program" render "$scene" -o "$scratch/frames/f-%d.exr" --frames 0 $frames -D light_x=1 --skip-existing \
    2>"$scratch/other-scene.log"
if grep -q "^rtspheres: frame 0: rendering afresh: .*f-0.exr was rendered from another scene" "$scratch/other-scene.log" &&
   grep -q "f-0.exr: 32x18, 8 spp in" "$scratch/other-scene.log"; then
    pass "--skip-existing renders again a frame made from another scene, and says so"
else
    fail "--skip-existing with another scene" "$(head -c 600 "$scratch/other-scene.log")"
fi
"$program" render "$scene" -o "$scratch/frames/f-%d.exr" --frames 1 --size 32x18 --spp 12 --seed 5 --skip-existing \
    2>"$scratch/other-options.log"
if grep -q "^rtspheres: frame 1: rendering afresh: .*f-1.exr was rendered with other options: 8 spp, this render 12" \
        "$scratch/other-options.log"; then
    pass "--skip-existing renders again a frame made with other options (8 spp, now 12), and says so"
else
    fail "--skip-existing with other options" "$(head -c 600 "$scratch/other-options.log")"
fi

# A partial one is resumed: a render cut short by --time-limit (its first pass only) is
# what an interrupt leaves as OUTPUT.partial.exr; --skip-existing continues it to the
# uninterrupted render (float rounding of mean * n, as --resume) and removes the partial.
long="--size 32x18 --spp 128 --seed 5"
"$program" render "$scene" -o "$scratch/whole.exr" $long --quiet
"$program" render "$scene" -o "$scratch/cut.exr" $long --time-limit 0.001 --quiet
mv "$scratch/cut.exr" "$scratch/cut.partial.exr"
partial_samples=$(metadata "$scratch/cut.partial.exr" samples_finished)
"$program" render "$scene" -o "$scratch/cut.exr" $long --skip-existing 2>"$scratch/resume.log"
if grep -q "^rtspheres: resuming: .*cut.partial.exr holds $partial_samples samples of this scene and options" \
        "$scratch/resume.log" && [ "$partial_samples" -lt $((32 * 18 * 128)) ] && [ ! -e "$scratch/cut.partial.exr" ] &&
   "$program" diff "$scratch/cut.exr" "$scratch/whole.exr" --fail 1e-5 --failpercent 0 >"$scratch/diff" 2>&1 &&
   [ "$(channel_range "$scratch/cut.exr" samples)" = "128 128" ]; then
    pass "--skip-existing resumes a partial ($partial_samples samples) to the uninterrupted image and removes it"
else
    fail "--skip-existing resumes a partial" "$(head -c 400 "$scratch/resume.log") $(head -c 300 "$scratch/diff")"
fi
# An adaptive render cut short (after 6 passes, as a time limit would stop it) leaves an
# incomplete output with its adaptive state (render.h): --skip-existing continues it to the
# uninterrupted image bit for bit, sample counts too.
adaptive="--size 32x18 --spp 128 --seed 5 --noise-threshold 0.1"
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/adaptive-whole.exr" $adaptive --quiet
# shellcheck disable=SC2086
RTSPHERES_TEST_STOP_AFTER_PASSES=6 "$program" render "$scene" -o "$scratch/adaptive-cut.exr" $adaptive \
    --pass-budget 100 --quiet
cut_samples=$(channel_mean "$scratch/adaptive-cut.exr" samples)
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/adaptive-cut.exr" $adaptive --skip-existing 2>"$scratch/adaptive-resume.log"
if grep -q "^rtspheres: resuming: .*adaptive-cut.exr is incomplete .*stopped by time.*; continuing it" \
        "$scratch/adaptive-resume.log" &&
   "$program" diff "$scratch/adaptive-cut.exr" "$scratch/adaptive-whole.exr" --fail 0 --failpercent 0 \
        >"$scratch/diff" 2>&1 &&
   [ "$(channel_range "$scratch/adaptive-cut.exr" samples)" = "$(channel_range "$scratch/adaptive-whole.exr" samples)" ] &&
   [ "$(channel_mean "$scratch/adaptive-cut.exr" samples)" = "$(channel_mean "$scratch/adaptive-whole.exr" samples)" ]; then
    pass "--skip-existing continues an adaptive render cut short ($cut_samples samples a pixel) bit for bit"
else
    fail "--skip-existing continues an adaptive render" "$(head -c 400 "$scratch/adaptive-resume.log") $(head -c 300 "$scratch/diff")"
fi
finish
