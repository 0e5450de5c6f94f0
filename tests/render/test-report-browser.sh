#!/bin/sh
# test-report-browser.sh: the HTML report of `rtspheres check --report` in a real browser,
# headless Chromium (Debian's `chromium`, listed in .ci/test-packages, which `make test`
# installs when missing; skipped, with the reason, when it is not there or cannot start). The report is copied to another folder first, as a CI
# artefact is, and opened from there: every image must load (the page's own script counts
# the images with a natural width into #image-check, read back with --dump-dom), a
# screenshot must show a page, nothing may come from the network, and the failing case
# comes first.
#   usage: sh tests/render/test-report-browser.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
work=$scratch/suite
mkdir -p "$work/golden"
cp scenes/materials/lambertian.txt "$work/scene.txt"
sed 's/^material red lambertian 0.8 0.25 0.2/material red lambertian 0.88 0.275 0.22/' "$work/scene.txt" \
    >"$work/brighter.txt"
"$program" render "$work/scene.txt" -o "$work/golden/base.exr" --size 64x36 --spp 16 --seed 1 --variance --quiet
cat >"$work/suite.txt" <<'SUITE'
render --size 64x36 --spp 16 --seed 1
case same scene.txt golden/base.exr
case brighter brighter.txt golden/base.exr
SUITE
"$program" check "$work/suite.txt" --report "$work/report" >"$scratch/check.out" 2>&1
code=$?
if [ "$code" = 1 ] && [ -s "$work/report/index.html" ]; then
    pass "check --report: one case fails, the report is written (exit 1)"
else fail "check --report" "exit $code: $(tr '\n' '|' <"$scratch/check.out")"; fi
# The CI artefact: the folder moved elsewhere.
cp -r "$work/report" "$scratch/artefact"
rm -rf "$work/report"
page=$scratch/artefact/index.html
images=$(grep -o '<img src="[^"]*"' "$page" | sed 's/<img src="//; s/"$//')
count=$(printf '%s\n' "$images" | grep -c .)
missing=""
for image in $images; do
    case $image in /* | *:*) missing="$missing $image(not relative)" ;; esac
    [ -s "$scratch/artefact/$image" ] || missing="$missing $image"
done
if [ "$count" = 8 ] && [ -z "$missing" ]; then
    pass "report: 8 previews (reference, new, difference, heat map of 2 cases), relative links to files in the folder"
else fail "report images" "$count images; missing or absolute:$missing"; fi
if grep -qiE '(src|href)="?[a-z]+://|url\(|@import' "$page"; then
    fail "report: nothing from the network" "$(grep -oiE '(src|href)="?[a-z]+://[^"]*|url\([^)]*\)|@import' "$page" | head -3)"
else pass "report: no network address, stylesheet or import (self-contained)"; fi
first=$(grep -o '<section class="case [^"]*"' "$page" | head -1)
if [ "$first" = '<section class="case FAIL"' ]; then pass "report: the failing case comes first"
else fail "report order" "first section: $first"; fi

# ---- the browser -----------------------------------------------------------------------
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
    why="chromium is not installed (make test-deps installs .ci/test-packages)"
    echo "SKIP report in a browser: $why"
    finish
    exit
fi
# chromium_run ARGUMENTS...: headless Chromium on the page with a fresh profile, killed
# after 90 s; stdout in $scratch/browser.out.
chromium_run() {
    rm -rf "$scratch/profile"
    timeout -k 5 90 "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --user-data-dir="$scratch/profile" "$@" "file://$page" >"$scratch/browser.out" 2>"$scratch/browser.err"
}
if ! chromium_run --dump-dom || ! grep -q 'id="image-check"' "$scratch/browser.out"; then
    echo "SKIP report in a browser: chromium does not start here: $(grep -v dbus "$scratch/browser.err" | tail -n 2 | tr '\n' ' ')"
    finish
    exit
fi
loaded=$(sed -n 's/.*id="image-check"[^>]*>images loaded: \([0-9]* of [0-9]*\)<.*/\1/p' "$scratch/browser.out")
if [ "$loaded" = "8 of 8" ]; then pass "report in Chromium: its script counts 8 of 8 images loaded"
else fail "report in Chromium: images loaded" "'$loaded': $(grep image-check "$scratch/browser.out" | head -c 300)"; fi
chromium_run --window-size=1000,1400 --screenshot="$scratch/shot.png"
if stats_of "$scratch/shot.png" && grep -q '^size: 1000x1400' "$scratch/stats" \
    && awk -v r="$(stat_range R)" 'BEGIN { split(r, v, " "); exit !(v[1] < 0.2 && v[2] > 0.8) }'; then
    pass "report in Chromium: a 1000x1400 screenshot with dark and light pixels (text and images)"
else fail "report screenshot" "$(head -n 3 "$scratch/stats" | tr '\n' ' ') R $(stat_range R)"; fi
finish
