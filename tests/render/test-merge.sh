#!/bin/sh
# test-merge.sh: `rtspheres merge` on real renders: sample-range parts, tiles and shards
# merge back into the single-machine render, and mismatched, overlapping or missing parts
# are refused with exit 2 and a message.
#   usage: sh tests/render/test-merge.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# The test scene and its whole render $full (lib.sh); nothing to compare without it.
render_split_scene || { finish; exit; }

# merge_ok NAME EXPECTED TOLERANCE PARTS...: merges PARTS into $scratch/NAME.exr and
# compares the result with EXPECTED by `diff --fail TOLERANCE --failpercent 0`; also
# checks that every pixel has 16 samples and the merged image says it is complete.
merge_ok() {
    merge_name=$1 merge_expected=$2 merge_tolerance=$3
    shift 3
    problem=$(merge_problem "$merge_expected" "$merge_tolerance" 16 "$scratch/$merge_name.exr" "$@")
    if [ -n "$problem" ]; then
        fail "$merge_name" "$problem"
    elif [ "$(stat_metadata spp)" != 16 ] || [ "$(stat_metadata complete)" != 1 ]; then
        fail "$merge_name" "metadata spp '$(stat_metadata spp)', complete '$(stat_metadata complete)'"
    elif grep -q merged_parts "$scratch/stats" && [ "$(stat_metadata merged_parts)" != $# ]; then
        # (checked where `stats` prints rtspheres:merged_parts)
        fail "$merge_name" "metadata merged_parts '$(stat_metadata merged_parts)', expected $#"
    else
        pass "$merge_name"
    fi
}

# refuse NAME PATTERN PARTS...: merging PARTS exits 2, says PATTERN (grep -E) on stderr and
# writes no output.
refuse() {
    refuse_name=$1 refuse_pattern=$2
    shift 2
    expect_refusal "$refuse_name" "$refuse_pattern" "$scratch/refused" \
        "$program" merge "$@" -o "$scratch/refused/out.exr"
}

# (a) Two sample-range parts, 0:6 and 6:10: the same samples as the full render, summed in
# another order, so equal within float rounding.
# The second part runs with a larger environment, which moves the stack: a scene hash
# that picked up uninitialised bytes (it hashes whole structs) would then differ, and
# parts of one render made on different machines would be refused.
render "$scratch/s0.exr" --samples 0:6 \
    && RTSPHERES_TEST_PADDING=$(printf '%0777d' 0) render "$scratch/s1.exr" --samples 6:10
merge_ok "merge-sample-ranges" "$full" 1e-5 "$scratch/s0.exr" "$scratch/s1.exr"

# (b) Three tiles: every pixel is the full render's, so bit-exact.
for i in 0 1 2; do render "$scratch/tile$i.exr" --tile $i/3; done
merge_ok "merge-tiles-exact" "$full" 0 "$scratch/tile2.exr" "$scratch/tile0.exr" "$scratch/tile1.exr"

# (c) Four sample shards.
for i in 0 1 2 3; do render "$scratch/shard$i.exr" --shard $i/4; done
merge_ok "merge-shards" "$full" 1e-5 "$scratch/shard0.exr" "$scratch/shard1.exr" "$scratch/shard2.exr" \
    "$scratch/shard3.exr"

# (d) Refusals.
render "$scratch/seed.exr" --samples 6:10 --seed 99
refuse "refuse-different-seed" "seed 1.*seed 99" "$scratch/s0.exr" "$scratch/seed.exr"
"$program" render "$scene" -o "$scratch/size.exr" --size 40x27 --spp 16 --quiet --samples 6:10
refuse "refuse-different-size" "48x27.*40x27" "$scratch/s0.exr" "$scratch/size.exr"
"$program" render scenes/materials/lambertian.txt -o "$scratch/other.exr" $size --spp 16 --quiet --samples 6:10
refuse "refuse-other-scene" "different scenes" "$scratch/s0.exr" "$scratch/other.exr"
# Shard 1/4 of 16 samples is 4:4, which shares samples 4 and 5 with part 0:6.
refuse "refuse-overlapping-samples" "s0.exr.*shard1.exr.*samples 4-5" "$scratch/s0.exr" "$scratch/shard1.exr"
refuse "refuse-missing-tile" "missing pieces: 432 pixels.*rows 9-17" "$scratch/tile0.exr" "$scratch/tile2.exr"
refuse "refuse-overlapping-tiles" "overlap" "$scratch/tile0.exr" "$scratch/tile1.exr" "$scratch/s0.exr"
refuse "refuse-unreadable-part" "nonexistent.exr" "$scratch/s0.exr" "$scratch/nonexistent.exr"
render "$scratch/denoised-part.exr" --samples 6:10 --denoise
refuse "refuse-denoised-part" "denoised-part.exr' is post-processed .rtspheres:postprocess \"denoise\".*rtspheres denoise" "$scratch/s0.exr" \
    "$scratch/denoised-part.exr"
# A PPM written by hand: an image, but with no samples channel and no metadata.
printf 'P6\n48 27\n255\n' >"$scratch/plain.ppm"
head -c 3888 /dev/zero >>"$scratch/plain.ppm"
refuse "refuse-part-without-samples" "plain.ppm.*samples" "$scratch/s0.exr" "$scratch/plain.ppm"

# -o naming a part is refused and the part is left as it was.
before=$(cksum <"$scratch/s0.exr")
"$program" merge "$scratch/s0.exr" "$scratch/s1.exr" -o "$scratch/s0.exr" >/dev/null 2>"$scratch/stderr"
got=$?
if [ "$got" = 2 ] && grep -q "is one of the parts" "$scratch/stderr" && [ "$(cksum <"$scratch/s0.exr")" = "$before" ]; then
    pass "refuse-overwriting-a-part"
else
    fail "refuse-overwriting-a-part" "exit $got; stderr: $(head -c 300 "$scratch/stderr")"
fi

# A missing tile is allowed with --allow-missing: its rows stay black with 0 samples.
name=allow-missing
if ! "$program" merge "$scratch/tile0.exr" "$scratch/tile2.exr" -o "$scratch/$name.exr" --allow-missing \
        --quiet 2>"$scratch/stderr"; then
    fail "$name" "merge failed: $(head -c 300 "$scratch/stderr")"
elif ! stats_of "$scratch/$name.exr" --crop 0,9,48,18 || [ "$(stat_range samples)" != "0 0" ] \
        || [ "$(stat_range R)" != "0 0" ] || [ "$(stat_metadata complete)" != 0 ]; then
    fail "$name" "missing rows: samples '$(stat_range samples)', R '$(stat_range R)';" \
        "complete '$(stat_metadata complete)'"
elif ! stats_of "$scratch/$name.exr" --crop 0,0,48,9 || [ "$(stat_range samples)" != "16 16" ]; then
    fail "$name" "tile 0 rows: samples '$(stat_range samples)', expected '16 16'"
else
    pass "$name"
fi

# Tiles with different sample ranges merge with a warning; the counts say what each has.
name=warn-uneven-tiles
"$program" render "$scene" -o "$scratch/tile1-8.exr" $size --spp 8 --quiet --tile 1/3
if ! "$program" merge "$scratch/tile0.exr" "$scratch/tile1-8.exr" "$scratch/tile2.exr" -o "$scratch/$name.exr" \
        --quiet 2>"$scratch/stderr"; then
    fail "$name" "merge failed: $(head -c 300 "$scratch/stderr")"
elif ! grep -q "warning:.*tile1-8.exr.*samples 0:8.*samples 0:16" "$scratch/stderr"; then
    fail "$name" "no warning naming the tile and its samples: $(head -c 300 "$scratch/stderr")"
elif ! stats_of "$scratch/$name.exr" || [ "$(stat_range samples)" != "8 16" ] || [ "$(stat_metadata spp)" != 8 ] \
        || [ "$(stat_metadata complete)" != 0 ]; then
    fail "$name" "samples '$(stat_range samples)', spp '$(stat_metadata spp)', complete '$(stat_metadata complete)'"
else
    pass "$name"
fi

# (e) AOV layers merge, so that a farm's render can be denoised: tiles merged are the whole
# render's layers and `rtspheres denoise` gives the untiled --denoise image bit for bit;
# sample ranges take the guides of the part that starts at 0 (the whole render's) and
# recombine variance.Y and the emission to float rounding, and their denoised image is
# the whole render's within 1e-5 (measured 9.5e-7 on the Cornell box).
cornell="scenes/cornell.txt --size 64x48 --seed 3 --spp 16 --quiet"
# shellcheck disable=SC2086
"$program" render $cornell -o "$scratch/aov-whole.exr" --denoise
for part in "tile-0 --tile 0/2" "tile-1 --tile 1/2" "range-0 --samples 0:8" "range-1 --samples 8:8"; do
    # shellcheck disable=SC2086
    "$program" render $cornell -o "$scratch/aov-${part%% *}.exr" --aovs ${part#* }
done
for kind in tile range; do
    name="merged ${kind}s with --aovs denoise to the whole render's --denoise image"
    tolerance=$([ $kind = tile ] && echo 0 || echo 1e-5)
    if ! "$program" merge "$scratch/aov-$kind-0.exr" "$scratch/aov-$kind-1.exr" -o "$scratch/aov-$kind.exr" -q ||
        ! "$program" denoise "$scratch/aov-$kind.exr" -o "$scratch/aov-$kind-denoised.exr" -q; then
        fail "$name" "merge or denoise failed"
    elif ! "$program" diff "$scratch/aov-$kind-denoised.exr" "$scratch/aov-whole.exr" --fail $tolerance \
            --failpercent 0 >/dev/null; then
        fail "$name" "$("$program" diff "$scratch/aov-$kind-denoised.exr" "$scratch/aov-whole.exr" | grep 'max error')"
    else pass "$name (within $tolerance)"; fi
done
"$program" render $cornell -o "$scratch/plain-range-1.exr" --samples 8:8
name="a part without AOV layers: the merge warns and keeps none"
if "$program" merge "$scratch/aov-range-0.exr" "$scratch/plain-range-1.exr" -o "$scratch/aov-mixed.exr" \
        2>"$scratch/aov-mixed.log" && grep -q "1 of the 2 parts have AOV layers" "$scratch/aov-mixed.log" &&
    ! "$program" stats "$scratch/aov-mixed.exr" | grep -q albedo; then
    pass "$name"
else fail "$name" "$(head -c 300 "$scratch/aov-mixed.log")"; fi

finish
