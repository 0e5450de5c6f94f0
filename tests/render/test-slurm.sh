#!/bin/sh
# test-slurm.sh: runs the Slurm scale-out test (tests/slurm/test-slurm.sh) as part of the
# render tests, so `make test` covers submit.sh, the job scripts and merge on a real
# single-node cluster. It installs the Slurm and munge packages when missing and takes
# about 13 s (about 18 s with the install).
#   usage: sh tests/render/test-slurm.sh PROGRAM SCRATCH_DIR
# SCRATCH_DIR is not used: the cluster keeps its state in a temporary directory of its
# own, which it removes.
set -u
exec sh "$(dirname "$0")/../slurm/test-slurm.sh" "$1"
