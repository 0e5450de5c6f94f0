#!/bin/sh
# run.sh: `make bench`: times the benchmark scenes (not a test: nothing here passes or
# fails on speed). Prints a table and appends one CSV row per scene to build/bench.csv:
#   date,scene,size,spp,triangles,seconds,samples_per_second,segments_per_second,
#   bvh_build_seconds,bytes_per_triangle,first_pass_seconds
# Knobs: BENCH_SPP (default 32) samples per pixel for the weekend scene.
#   usage: sh tests/bench/run.sh PROGRAM
set -eu
program=$1
spp=${BENCH_SPP:-32}
work=build/bench
mkdir -p "$work"
csv=build/bench.csv
[ -f "$csv" ] || echo "date,scene,size,spp,triangles,seconds,samples_per_second,segments_per_second,bvh_build_seconds,bytes_per_triangle,first_pass_seconds" >"$csv"

bench() {
    name=$1 scene=$2 size=$3 spp=$4
    shift 4
    out="$work/$name.exr"
    "$program" render "$scene" -o "$out" --size "$size" --spp "$spp" --verbose "$@" 2>"$work/$name.log" >/dev/null
    summary=$(grep -- "-> $out" "$work/$name.log" | tail -1)
    details=$(grep "rtspheres: scene:" "$work/$name.log" | tail -1)
    seconds=$(echo "$summary" | sed -n 's/.* spp in \([0-9.]*\) s .*/\1/p')
    samples=$(echo "$summary" | sed -n 's/.*(\([0-9.e+]*\) samples\/s.*/\1/p')
    segments=$(echo "$summary" | sed -n 's/.*, \([0-9.e+]*\) path segments\/s.*/\1/p')
    triangles=$(echo "$details" | sed -n 's/.*(\([0-9]*\) triangles).*/\1/p')
    build=$(echo "$details" | sed -n 's/.*built in \([0-9.]*\) s.*/\1/p')
    per_triangle=$(echo "$details" | sed -n 's/.*bytes (\([0-9.]*\) per triangle.*/\1/p')
    first=$(echo "$details" | sed -n 's/.*first pass done \([0-9.]*\) s.*/\1/p')
    printf '%-14s %-9s %4s spp %8s tris %7s s %9s samples/s %9s segments/s  BVH %6s s %6s B/tri  first pass %s s\n' \
        "$name" "$size" "$spp" "$triangles" "$seconds" "$samples" "$segments" "$build" "$per_triangle" "$first"
    echo "$(date -u +%Y-%m-%dT%H:%M:%SZ),$name,$size,$spp,$triangles,$seconds,$samples,$segments,$build,$per_triangle,$first" >>"$csv"
}

"$program" info | sed -n 's/^GL renderer: *//p' | sed 's/^/renderer: /'
bench weekend scenes/weekend.txt 1200x675 "$spp" --max-depth 50
bench three-balls scenes/three-balls.txt 640x360 64
# The seed's quick-sweep mode: a Whitted frame with soft shadows (POV-Ray renders such a
# frame with an 8x8 area light in about 1.6 s on two cores).
bench three-balls-whitted scenes/three-balls.txt 640x360 4 --integrator whitted

# Meshes of growing size (icospheres of subdivision 3, 5, 6, 8: 1,280 to 1,310,720
# triangles), the same small frame each: time per sample should grow about like log n.
cc -std=c11 -O2 scenes/generators/assets.c -lm -o "$work/assets"
for level in 3 5 6 8; do
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
    bench "mesh-$level" "$work/mesh-$level.txt" 320x240 16
done
echo "results appended to $csv"
