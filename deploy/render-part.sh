#!/usr/bin/env bash
# One job of a render split across a cluster: job INDEX of COUNT renders an
# equal share of every pixel's samples and writes it to
# $PARTS/part-INDEX.accum; 'rtgi merge' puts the parts together into the
# image a single render would have made, byte for byte.
#
# Usage: render-part.sh INDEX COUNT
# Environment:
#   SCENE       scene file, as the render reads it (required)
#   SPP         samples per pixel of the whole render (required)
#   PARTS       folder shared by all jobs, for parts and checkpoints (required)
#   RTGI        the rtgi binary [default: rtgi on the PATH]
#   TIME_LIMIT  seconds this job may run; the part is checkpointed before then,
#               and a job run again (requeued, restarted) resumes it [default: none]
#   RTGI_ARGS   further options, the same for every job (size, seed, camera, ...)
# Every job must get the same SCENE, SPP and RTGI_ARGS: 'rtgi merge' refuses
# parts of different renders.
set -euo pipefail

if [ $# -ne 2 ]; then
    echo "usage: $0 INDEX COUNT" >&2
    exit 2
fi
index=$1
count=$2
: "${SCENE:?set SCENE to the scene file}"
: "${SPP:?set SPP to the samples per pixel of the whole render}"
: "${PARTS:?set PARTS to a folder all jobs share}"
rtgi=${RTGI:-rtgi}

if ! [ "$index" -ge 0 ] 2>/dev/null || ! [ "$index" -lt "$count" ] 2>/dev/null; then
    echo "$0: job index $index is not in 0..$count" >&2
    exit 2
fi

# Samples [from, to) of every pixel: shares that differ by at most one sample.
from=$(( index * SPP / count ))
to=$(( (index + 1) * SPP / count ))
if [ "$from" -eq "$to" ]; then
    echo "$0: job $index of $count has no samples (only $SPP samples per pixel)" >&2
    exit 0
fi

part="$PARTS/part-$index.accum"
checkpoint="$PARTS/part-$index.checkpoint.accum"
if [ -f "$part" ]; then
    echo "$0: $part is already done"
    exit 0
fi

# The part is written under a hidden name and renamed only once complete, so
# that a part file always holds all of its job's samples.
unfinished="$PARTS/.part-$index.accum"
options=(render "$SCENE" --spp "$SPP" --samples "$from..$to" --checkpoint "$checkpoint" -o "$unfinished")
if [ -f "$checkpoint" ]; then
    options+=(--resume "$checkpoint")
fi
if [ -n "${TIME_LIMIT:-}" ]; then
    options+=(--time-limit "$TIME_LIMIT")
fi
# RTGI_ARGS is split on spaces on purpose: it holds several options.
# shellcheck disable=SC2206
options+=(${RTGI_ARGS:-})

log="$PARTS/part-$index.log"
status=0
"$rtgi" "${options[@]}" | tee "$log" || status=$?
if [ "$status" -ne 0 ]; then
    # 130/143: stopped by a signal (preemption, scancel, the scheduler's own
    # time limit) after saving the checkpoint; running the job again resumes it.
    echo "$0: job $index stopped (exit $status); run it again to resume from $checkpoint" >&2
    exit "$status"
fi
if grep -q '^stopped' "$log"; then
    # The time limit came first: the checkpoint holds the samples done.
    rm -f "$unfinished"
    echo "$0: job $index reached its time limit; run it again to resume from $checkpoint" >&2
    exit 75
fi
mv "$unfinished" "$part"
rm -f "$checkpoint"
echo "$0: wrote $part (samples $from..$to of $SPP)"
