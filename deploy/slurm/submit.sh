#!/usr/bin/env bash
# Submits a split render and its merge to Slurm.
#
#   deploy/slurm/submit.sh TASKS SCENE SPP OUTPUT [rtgi render options...]
#   deploy/slurm/submit.sh 16 scenes/cornell-box.toml 4096 cornell.exr --width 1024 --height 1024
#
# Parts and logs go to $PARTS [default: ./parts-<output name>].
set -euo pipefail

if [ $# -lt 4 ]; then
    sed -n '2,7p' "$0" >&2
    exit 2
fi
tasks=$1 scene=$2 spp=$3 output=$4
shift 4
here=$(cd "$(dirname "$0")/.." && pwd)
parts=${PARTS:-$PWD/parts-$(basename "${output%.*}")}
mkdir -p "$parts"

array=$(SCENE=$scene SPP=$spp PARTS=$parts RTGI_ARGS="$*" ARRAY_COUNT=$tasks DEPLOY_DIR=$here \
    sbatch --parsable --export=ALL --array=0-$((tasks - 1)) "$here/slurm/render.sbatch")
merge=$(PARTS=$parts OUTPUT=$output sbatch --parsable --export=ALL --dependency=afterok:"$array" \
    "$here/slurm/merge.sbatch")
echo "render array $array ($tasks tasks), merge $merge; parts in $parts"
