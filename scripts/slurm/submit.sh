#!/bin/sh
# submit.sh: renders a scene on a Slurm cluster as a job array of shards plus a merge job
# that runs only when every shard has succeeded.
#
#   scripts/slurm/submit.sh SCENE OUTPUT.exr --shards N [--partition P] [--parts DIR]
#       [--array LIST] [-- RENDER OPTIONS...]
#
#   SCENE          the scene file
#   OUTPUT.exr     the merged image
#   --shards N     split the work into N shards (array tasks 0 .. N-1); by samples unless
#                  the render options say --shard-by tiles
#   --partition P  the Slurm partition (default: the cluster's default)
#   --parts DIR    where the parts go (default: OUTPUT without .exr, plus .parts/);
#                  the job logs go to DIR/logs/
#   --array LIST   submit only these array tasks, e.g. 3,5 to render failed shards again
#                  (with the same SCENE, --shards and render options as the first time);
#                  the merge job then waits for them and merges all N parts
#   RENDER OPTIONS passed to every `rtspheres render`, e.g. -- --spp 1024 --size 1920x1080
#
# An animation: with --frames among the render options, OUTPUT is a directory; the tasks
# render their shares of the frames (--shard-by frames) to OUTPUT/frame-NNNN.exr, their logs go
# to OUTPUT/logs/, no merge job is submitted and merge_job= is printed empty. Submitting
# the same command again (or requeueing a task: scontrol requeue JOBID_TASK) renders only
# the frames that are not complete: the tasks run with --skip-existing.
#
# Environment: RTSPHERES, the rtspheres program the jobs run (default: `rtspheres` on
# PATH, else the one built in this checkout); SLURM_CONF and the SBATCH_* variables of
# sbatch work as usual (e.g. SBATCH_ACCOUNT, SBATCH_TIMELIMIT).
#
# Prints two lines a shell can eval, then says what it did on stderr:
#   render_job=JOBID
#   merge_job=JOBID
# The merge job is submitted with --dependency=afterok:RENDER --kill-on-invalid-dep=yes:
# when a shard fails, Slurm cancels the merge instead of leaving it pending forever.
# `scontrol show job RENDER` (or `sacct -j RENDER` with accounting) shows which task
# failed, and DIR/logs/render-RENDER_TASK.log why. Exit 0 when both jobs were submitted, 2
# for bad arguments, 1 when sbatch failed.
set -eu

usage() {
    echo "usage: submit.sh SCENE OUTPUT.exr --shards N [--partition P] [--parts DIR] [--array LIST] [-- render options]" >&2
    exit 2
}

# absolute PATH: PATH made absolute (jobs may start in another directory).
absolute() {
    case $1 in
    /*) printf '%s\n' "$1" ;;
    *) printf '%s/%s\n' "$(pwd)" "$1" ;;
    esac
}

[ $# -ge 2 ] || usage
scene=$1
output=$2
shift 2
shards=""
partition=""
part_dir=""
array=""
while [ $# -gt 0 ]; do
    case $1 in
    --shards) [ $# -ge 2 ] || usage; shards=$2; shift 2 ;;
    --partition) [ $# -ge 2 ] || usage; partition=$2; shift 2 ;;
    --parts) [ $# -ge 2 ] || usage; part_dir=$2; shift 2 ;;
    --array) [ $# -ge 2 ] || usage; array=$2; shift 2 ;;
    --) shift; break ;;
    *) echo "submit.sh: unknown option '$1'" >&2; usage ;;
    esac
done
case $shards in
'' | *[!0-9]* | 0) echo "submit.sh: --shards wants a whole number of at least 1" >&2; usage ;;
esac
[ -f "$scene" ] || { echo "submit.sh: no scene file '$scene'" >&2; exit 2; }
frames=no
for option in "$@"; do
    case $option in
    --frames | --frames=*) frames=yes ;;
    esac
done
case $frames/$output in
yes/*.exr) echo "submit.sh: with --frames the output is a directory for the frames, not '$output'" >&2; exit 2 ;;
yes/*) ;;
*/*.exr) ;;
*) echo "submit.sh: the output should be .exr (it keeps the samples channel and metadata)" >&2; exit 2 ;;
esac

here=$(cd "$(dirname "$0")" && pwd)
if [ -z "${RTSPHERES:-}" ]; then
    if command -v rtspheres >/dev/null 2>&1; then
        RTSPHERES=$(command -v rtspheres)
    elif [ -x "$here/../../rtspheres" ]; then
        RTSPHERES=$(cd "$here/../.." && pwd)/rtspheres
    else
        echo "submit.sh: no rtspheres program: put it on PATH or set RTSPHERES" >&2
        exit 2
    fi
fi
RTSPHERES=$(absolute "$RTSPHERES")
export RTSPHERES
scene=$(absolute "$scene")
output=$(absolute "$output")
if [ "$frames" = yes ]; then
    [ -z "$part_dir" ] || { echo "submit.sh: --parts does not go with --frames (the frames go to OUTPUT)" >&2; exit 2; }
    part_dir=$output
fi
[ -n "$part_dir" ] || part_dir=${output%.exr}.parts
part_dir=$(absolute "$part_dir")
mkdir -p "$part_dir/logs"
[ -n "$array" ] || array=0-$((shards - 1))

partition_option=""
[ -z "$partition" ] || partition_option=--partition=$partition

# --parsable prints "JOBID" (or "JOBID;CLUSTER" on a federation): keep the id.
render_job=$(sbatch --parsable $partition_option --array="$array" \
    --output="$part_dir/logs/render-%A_%a.log" \
    "$here/render-array.sbatch" "$scene" "$part_dir" "$shards" "$@") || {
    echo "submit.sh: sbatch of the render array failed" >&2
    exit 1
}
render_job=${render_job%%;*}
if [ "$frames" = yes ]; then
    echo "render_job=$render_job"
    echo "merge_job="
    echo "submit.sh: render array $render_job (tasks $array of $shards) -> frames in $part_dir; nothing to merge" >&2
    exit 0
fi
merge_job=$(sbatch --parsable $partition_option --dependency="afterok:$render_job" --kill-on-invalid-dep=yes \
    --output="$part_dir/logs/merge-%j.log" \
    "$here/merge.sbatch" "$output" "$part_dir" "$shards") || {
    echo "submit.sh: sbatch of the merge job failed; cancel the render array with: scancel $render_job" >&2
    exit 1
}
merge_job=${merge_job%%;*}
echo "render_job=$render_job"
echo "merge_job=$merge_job"
echo "submit.sh: render array $render_job (tasks $array of $shards) -> $part_dir; merge $merge_job -> $output" >&2
