#!/bin/sh
# test-light-groups.sh: --light-groups and rtspheres relight end to end. The layers sum to
# the beauty image (relight with every weight 1, compared pixel by pixel within float
# rounding: 1e-4 on values up to about 10, a few ulps of a sum of samples) for every golden
# scene at 32x18 and 4 spp with its options (both integrators, volumes, environment), and
# for a scene with every kind of light in its own group with light sampling on and off;
# relight writes 8-bit outputs tone-mapped as render does; bad input is exit 2. The
# statistics (a layer is its light alone, relight by k is the light times k) are
# tests/unit/test_light_groups.c. Parts of split renders (sample ranges, tiles) merge
# with their layers. About 85 s in `make test` on the loaded machine (43 s of CPU).
#   usage: sh tests/render/test-light-groups.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"

# sums NAME EXR: one check: relighting EXR with every weight 1 gives its R, G, B back.
sums() {
    if ! "$program" relight "$2" -o "$scratch/sum.exr" --quiet 2>"$scratch/stderr"; then
        fail "$1" "relight failed: $(head -c 300 "$scratch/stderr")"
    elif "$program" diff "$2" "$scratch/sum.exr" --fail 1e-4 --failpercent 0 >"$scratch/diff" 2>&1; then
        pass "$1 ($(grep '^max error' "$scratch/diff"))"
    else
        fail "$1" "the layers do not sum to the image: $(tr '\n' ' ' <"$scratch/diff" | head -c 300)"
    fi
}

# The golden suite's cases: `case NAME SCENE GOLDEN [OPTIONS...]` (a suite file of check).
grep '^case ' "$here/golden-scenes.txt" | {
    while read -r _ name scene _ extra; do
        # shellcheck disable=SC2086 # $extra is a list of options; the later --size wins
        if "$program" render "$scene" -o "$scratch/$name.exr" --quiet $extra --size 32x18 --spp 4 --light-groups \
            2>"$scratch/stderr"; then
            sums "layers sum to the image: $name" "$scratch/$name.exr"
        else
            fail "layers sum to the image: $name" "render failed: $(head -c 300 "$scratch/stderr")"
        fi
    done
    finish
} || failures=$((failures + 1))

scene=$here/scenes/light-groups.txt
# The last: adaptive sampling traces a margin around a crop, which the layers lose with the
# image (core/render.c crop_to_region).
for options in "" "--light-sampling off" "--integrator whitted" "--sampler independent" \
    "--noise-threshold 0.1 --spp 64 --crop 8,4,40,22"; do
    # shellcheck disable=SC2086
    "$program" render "$scene" -o "$scratch/groups.exr" --quiet $options --light-groups
    sums "every kind of light in a group ${options:-(defaults)}" "$scratch/groups.exr"
done

# Layers held in registers through a pass (glsl/light_groups.glsl: up to 8 groups) are bit
# for bit the layers of the image's way (RTSPHERES_TEST_LIGHT_GROUP_IMAGE=1), here with
# passes of a few segments against passes as long as the device allows, so that every
# pass's load and store is on the way: the image and each group alone (relight with the
# others at 0), for both integrators (Whitted adds its lights inside a loop of its own).
same_layers() {
    name=$1
    shift
    RTSPHERES_TEST_LIGHT_GROUP_IMAGE=1 "$program" render "$scene" -o "$scratch/image-way.exr" --quiet --light-groups \
        --pass-budget 50000 "$@"
    "$program" render "$scene" -o "$scratch/held.exr" --quiet --light-groups --pass-budget 300 "$@"
    differing=""
    for group in "" default sky panel key fill sun; do
        for way in image-way held; do
            if [ -z "$group" ]; then
                cp "$scratch/$way.exr" "$scratch/$way-layer.exr"
            else
                weights=""
                for other in default sky panel key fill sun; do
                    [ "$other" = "$group" ] || weights="$weights --group $other=0"
                done
                # shellcheck disable=SC2086 # $weights is a list of options
                "$program" relight "$scratch/$way.exr" -o "$scratch/$way-layer.exr" --quiet $weights
            fi
        done
        "$program" diff "$scratch/image-way-layer.exr" "$scratch/held-layer.exr" --fail 0 --failpercent 0 --quiet \
            >/dev/null 2>&1 || differing="$differing ${group:-image}"
    done
    if [ -z "$differing" ]; then pass "$name: the layers held in registers are the image's way's, bit for bit"
    else fail "$name: the layers held in registers are the image's way's" "differing:$differing"; fi
}
same_layers "path tracing"
same_layers "Whitted" --integrator whitted

# The layers are named by the scene's groups, default first, and listed in the metadata.
"$program" render "$scene" -o "$scratch/groups.exr" --quiet --light-groups
groups=$(metadata "$scratch/groups.exr" light_groups)
if [ "$groups" = "default,sky,panel,key,fill,sun" ]; then pass "rtspheres:light_groups lists the groups"
else fail "rtspheres:light_groups lists the groups" "'$groups'"; fi
# A render a time limit ended names its groups too (relight finds the layers by them).
"$program" render "$scene" -o "$scratch/timed.exr" --quiet --light-groups --size 16x9 --spp 1000000 --time-limit 0.5
stats_of "$scratch/timed.exr"
timed="$(stat_metadata stop_reason) $(stat_metadata light_groups)"
if [ "$timed" = "time default,sky,panel,key,fill,sun" ]; then pass "a time-limited render lists its light groups"
else fail "a time-limited render lists its light groups" "stop reason and groups: '$timed'"; fi
stats_of "$scratch/groups.exr"
missing=""
for group in default sky panel key fill sun; do
    for c in R G B; do [ -n "$(stat_mean "$group.$c")" ] || missing="$missing $group.$c"; done
done
if [ -z "$missing" ]; then pass "a layer NAME.R/G/B per group"; else fail "a layer NAME.R/G/B per group" "missing$missing"; fi
# The key light's layer is lit: its mean is a real share of the image.
key=$(stat_mean key.R) all=$(stat_mean R)
if awk -v k="$key" -v a="$all" 'BEGIN { exit !(k > 0.05 * a && k < a) }'; then pass "the key layer holds light"
else fail "the key layer holds light" "key.R mean $key of R $all"; fi

# Split renders merge their layers (rtspheres merge) as they merge the colour: two sample
# ranges of the 16 (0:5 by --shard 0/3, 5:11 by --samples, uneven so that the weights
# matter) within float rounding of the whole render's groups.exr, two tiles bit for bit;
# after the merge the layers still sum to the image, pixel by pixel, and each layer
# matches the whole render's (the key layer pixel by pixel through relight, every
# layer's mean, min and max through stats).
"$program" render "$scene" -o "$scratch/half0.exr" --quiet --light-groups --shard 0/3
"$program" render "$scene" -o "$scratch/half1.exr" --quiet --light-groups --samples 5:11
"$program" render "$scene" -o "$scratch/band0.exr" --quiet --light-groups --tile 0/2
"$program" render "$scene" -o "$scratch/band1.exr" --quiet --light-groups --shard 1/2 --shard-by tiles
"$program" relight "$scratch/groups.exr" -o "$scratch/whole-key.exr" --quiet --group default=0 --group sky=0 \
    --group panel=0 --group fill=0 --group sun=0
"$program" stats "$scratch/groups.exr" | grep '^channel .*\.[RGB]:' >"$scratch/whole.layers"
for split in "samples 1e-5 half0 half1" "tiles 0 band0 band1"; do
    # shellcheck disable=SC2086 # $split is a list of words
    set -- $split
    kind=$1 tolerance=$2 merged=$scratch/merged-$1.exr
    problem=$(merge_problem "$scratch/groups.exr" "$tolerance" 16 "$merged" "$scratch/$3.exr" "$scratch/$4.exr")
    if [ -n "$problem" ]; then fail "two $kind parts with light groups merge into the whole render" "$problem"
    else pass "two $kind parts with light groups merge into the whole render (within $tolerance)"; fi
    groups=$(metadata "$merged" light_groups)
    if [ "$groups" = "default,sky,panel,key,fill,sun" ]; then pass "the merge of $kind parts lists the groups"
    else fail "the merge of $kind parts lists the groups" "'$groups'"; fi
    sums "the layers sum to the image after merging $kind parts" "$merged"
    "$program" relight "$merged" -o "$scratch/merged-key.exr" --quiet --group default=0 --group sky=0 \
        --group panel=0 --group fill=0 --group sun=0
    if "$program" diff "$scratch/merged-key.exr" "$scratch/whole-key.exr" --fail "$tolerance" --failpercent 0 \
        >"$scratch/diff" 2>&1; then pass "the merged key layer of $kind parts is the whole render's (within $tolerance)"
    else fail "the merged key layer of $kind parts is the whole render's" "$(tr '\n' ' ' <"$scratch/diff" | head -c 300)"; fi
    "$program" stats "$merged" | grep '^channel .*\.[RGB]:' >"$scratch/merged.layers"
    # Each layer's mean, min and max: equal to the whole's, to the tolerance relative to each.
    worst=$(paste -d ' ' "$scratch/whole.layers" "$scratch/merged.layers" | awk -v t="$tolerance" '
        { n++; if ($1 != $9 || $2 != $10) { bad = bad " " $2 "<>" $10; next }
          for (k = 4; k <= 8; k += 2) { e = $k; g = $(k + 8); d = e - g; if (d < 0) d = -d; a = e < 0 ? -e : e
              if (d > t * a) bad = bad " " $2 " " $(k - 1) " " g " vs " e } }
        END { if (n != 18) bad = bad " " n " layer channels"; print bad }')
    if [ -z "$worst" ]; then pass "every merged layer of $kind parts has the whole render's mean, min and max"
    else fail "every merged layer of $kind parts has the whole render's mean, min and max" "$worst"; fi
done

# Relighting to 8 bits: with every weight 1 it is the render's own 8-bit image (exposure
# and tone mapping as render applies them), within one 8-bit step.
"$program" render "$scene" -o "$scratch/render.png" --quiet --exposure 1 --tonemap aces
"$program" relight "$scratch/groups.exr" -o "$scratch/relit.png" --quiet --exposure 1 --tonemap aces
if "$program" diff "$scratch/render.png" "$scratch/relit.png" --fail 0.0040 --failpercent 0 >"$scratch/diff" 2>&1
then pass "relight to PNG is render's PNG"
else fail "relight to PNG is render's PNG" "$(tr '\n' ' ' <"$scratch/diff" | head -c 300)"; fi
# Turning every group off but one leaves that group's layer as the image.
"$program" relight "$scratch/groups.exr" -o "$scratch/key.exr" --quiet --group default=0 --group sky=0 \
    --group panel=0 --group fill=0 --group sun=0,0,0
key_only=$(channel_mean "$scratch/key.exr" R)
if within "$key_only" "$key" 1e-5; then pass "relight with the others at 0 is the key layer"
else fail "relight with the others at 0 is the key layer" "R mean $key_only, key.R mean $key"; fi
# A relit EXR keeps its weighted layers: relighting it again composes the weights.
"$program" relight "$scratch/key.exr" -o "$scratch/key2.exr" --quiet --group key=2
twice=$(channel_mean "$scratch/key2.exr" R)
if within "$twice" "$(awk -v k="$key" 'BEGIN { print 2 * k }')" 1e-5; then pass "a relit EXR relights again"
else fail "a relit EXR relights again" "R mean $twice, expected 2 x $key"; fi

# The relit files say what their render said and what was done to it, in order; a relit
# file is no merge part (its colour is no longer the render's means).
stats_of "$scratch/key2.exr"
steps="relight default=0 sky=0 panel=0 fill=0 sun=0; relight key=2"
if [ "$(stat_metadata postprocess)" = "$steps" ] &&
    [ "$(stat_metadata scene_hash)" = "$(metadata "$scratch/groups.exr" scene_hash)" ] &&
    [ "$(stat_metadata spp)" = "$(metadata "$scratch/groups.exr" spp)" ] && [ -z "$(stat_metadata options_hash)" ] &&
    [ "$(stat_metadata light_groups)" = "default,sky,panel,key,fill,sun" ]; then
    pass "a relit file carries its render's metadata and the relight steps"
else fail "relit metadata" "postprocess '$(stat_metadata postprocess)', scene_hash '$(stat_metadata scene_hash)'"; fi
if [ "$(metadata "$scratch/relit.png" postprocess)" = relight ] && [ -z "$(metadata "$scratch/relit.png" light_groups)" ]
then pass "a relit PNG records the relight, and no layers it does not have"
else fail "relit PNG metadata" "postprocess '$(metadata "$scratch/relit.png" postprocess)'"; fi

# Bad input: exit 2 with a message, nothing written.
mkdir -p "$scratch/out"
expect_refusal "a relit file as a merge part" "is post-processed .rtspheres:postprocess \"relight default=0 .*; relight key=2\"." "$scratch/out" \
    "$program" merge "$scratch/groups.exr" "$scratch/key2.exr" -o "$scratch/out/x.exr"
"$program" render "$scene" -o "$scratch/plain.exr" --quiet
mkdir -p "$scratch/out"
expect_refusal "relight of a file without layers" "has no light group layers" "$scratch/out" \
    "$program" relight "$scratch/plain.exr" -o "$scratch/out/x.exr"
expect_refusal "relight of a group the file lacks" "no light group 'rim' in the image; it has default,sky,panel,key,fill,sun" \
    "$scratch/out" "$program" relight "$scratch/groups.exr" -o "$scratch/out/x.png" --group rim=2
expect_refusal "a weight that is no number" "not a number SCALE or three numbers R,G,B" "$scratch/out" \
    "$program" relight "$scratch/groups.exr" -o "$scratch/out/x.png" --group key=1,2
expect_refusal "relight onto its input" "is the input" "$scratch/out" \
    "$program" relight "$scratch/groups.exr" -o "$scratch/groups.exr"
expect_refusal "--light-groups to a PNG" "only .exr keeps" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/x.png" --light-groups
expect_refusal "--light-groups with --denoise" "no longer sum to the image" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/x.exr" --light-groups --denoise
expect_refusal "--light-groups with --resume" "a partial file keeps no layers .*render the rest as a sample range" \
    "$scratch/out" "$program" render "$scene" -o "$scratch/out/x.exr" --light-groups --resume "$scratch/plain.exr"
printf 'light point 0 1 0 group a.b\n' >"$scratch/bad.txt"
expect_refusal "a group name with a dot" "bad.txt:1:25: light group name 'a.b' has a '.'" "$scratch/out" \
    "$program" render "$scratch/bad.txt" -o "$scratch/out/x.exr" --light-groups
finish
