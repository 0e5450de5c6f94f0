# golden-options.sh: the render options of every golden image (sourced by the golden
# test and by `make golden`, so both always agree).
golden_render_options="--size 160x90 --spp 64 --seed 1 --quiet"
