#!/usr/bin/env bash
# One job of a render split across a cluster: job INDEX of COUNT renders an
# equal share of every pixel's samples and writes it to
# $PARTS/part-INDEX.accum; 'rtgi merge' puts the parts together into the
# image a single render would have made, byte for byte.
#
# Usage: render-part.sh INDEX COUNT
# Environment:
#   SCENE         scene file, as the render reads it on this node (required)
#   SPP           samples per pixel of the whole render (required)
#   PARTS         folder shared by all jobs, for parts, checkpoints and logs (required)
#   RTGI          the rtgi binary [default: rtgi on the PATH]
#   TIME_LIMIT    seconds this job may run; the part is checkpointed before then,
#                 and a job run again (requeued, restarted) resumes it [default: none]
#   RTGI_THREADS  threads for rtgi [default: every CPU this job may use]
#   RTGI_ARGS     further 'rtgi render' options, the same for every job (size,
#                 seed, camera, ...); not those this script sets (--spp, --samples,
#                 --tile, --checkpoint, --resume, -o, --time-limit, and --threads
#                 when RTGI_THREADS is set)
# Every job must get the same SCENE, SPP and RTGI_ARGS: a part or checkpoint
# of another render is refused (exit 3), and so is merging it.
#
# Exit status, and what to do:
#   0        the part is done (now, or by an earlier run, checked to be of this render)
#   75       stopped by TIME_LIMIT; the checkpoint holds the samples done: run the job again to resume
#   130/143  stopped by SIGINT/SIGTERM (scancel, preemption, the scheduler's time limit) after
#            saving the checkpoint: run the job again to resume
#   2        bad arguments or environment, said on standard error: fix them (running again cannot help)
#   3        PARTS holds a part or checkpoint of another render: give this render a folder of its
#            own, or clear that one
#   1        rtgi failed (a scene that does not load, a full disk, ...), said in the log:
#            fix the cause (running again cannot help until then)
#
# Everything rtgi prints goes to $PARTS/logs/part-INDEX.log, each run appended
# under a line naming its start, and is also printed here once rtgi ends.
set -euo pipefail

fail() {
    local status=$1
    shift
    echo "$0: $*" >&2
    exit "$status"
}

if [ $# -ne 2 ]; then
    fail 2 "usage: $0 INDEX COUNT"
fi
index=$1
count=$2
: "${SCENE:?set SCENE to the scene file}"
: "${SPP:?set SPP to the samples per pixel of the whole render}"
: "${PARTS:?set PARTS to a folder all jobs share}"
rtgi=${RTGI:-rtgi}

is_count() { [[ $1 =~ ^[0-9]+$ ]] && [ "$1" -gt 0 ]; }
is_count "$count" || fail 2 "the job count '$count' is not a whole number above 0"
is_count "$SPP" || fail 2 "SPP='$SPP' is not a whole number above 0"
if ! [[ $index =~ ^[0-9]+$ ]] || [ "$index" -ge "$count" ]; then
    fail 2 "job index '$index' is not in 0..$((count - 1)) (the render has $count jobs)"
fi
[ -f "$SCENE" ] || fail 2 "SCENE=$SCENE: no such file on this node (in $(pwd)); give a path every node can read"
command -v "$rtgi" >/dev/null 2>&1 ||
    fail 2 "'$rtgi' is not on this node's PATH; install rtgi there, or set RTGI to its path"
# The options this script sets itself may not come twice: clap refuses that,
# and every job would fail the same way.
# RTGI_ARGS is split on spaces on purpose: it holds several options.
# shellcheck disable=SC2206
user_options=(${RTGI_ARGS:-})
for word in "${user_options[@]}"; do
    case $word in
        --spp | --spp=* | --samples | --samples=* | --tile | --tile=* | --checkpoint | --checkpoint=* | \
            --resume | --resume=* | -o | --output | --output=* | --time-limit | --time-limit=*)
            fail 2 "RTGI_ARGS has $word, which this script sets itself (SPP, the job's share, its checkpoint" \
                "and part, TIME_LIMIT); remove it"
            ;;
        --threads | --threads=* | -t | -t[0-9]*)
            if [ -n "${RTGI_THREADS:-}" ]; then
                fail 2 "RTGI_ARGS has $word, and RTGI_THREADS=$RTGI_THREADS sets the threads too; give one of them"
            fi
            ;;
    esac
done

# Samples [from, to) of every pixel: shares that differ by at most one sample.
from=$((index * SPP / count))
to=$(((index + 1) * SPP / count))
if [ "$from" -eq "$to" ]; then
    echo "$0: job $index of $count has no samples (only $SPP samples per pixel)"
    exit 0
fi

mkdir -p "$PARTS/logs"
part="$PARTS/part-$index.accum"
checkpoint="$PARTS/part-$index.checkpoint.accum"
# The part is written under a hidden name and renamed only once complete, so
# that a part file always holds all of its job's samples.
unfinished="$PARTS/.part-$index.accum"
log="$PARTS/logs/part-$index.log"

options=(render "$SCENE" --spp "$SPP" --samples "$from..$to" --checkpoint "$checkpoint" -o "$unfinished")
if [ -f "$part" ]; then
    # Done by an earlier run, perhaps of another render in the same folder:
    # resuming it makes rtgi compare its identity (scene, options, seed,
    # version) with this render's, and a complete part renders nothing more.
    options+=(--resume "$part")
    what="checking $part, done by an earlier run"
elif [ -f "$checkpoint" ]; then
    options+=(--resume "$checkpoint")
    what="resuming from $checkpoint"
    if [ -n "${TIME_LIMIT:-}" ]; then
        options+=(--time-limit "$TIME_LIMIT")
    fi
else
    what="rendering samples $from..$to of $SPP"
    if [ -n "${TIME_LIMIT:-}" ]; then
        options+=(--time-limit "$TIME_LIMIT")
    fi
fi
if [ -n "${RTGI_THREADS:-}" ]; then
    options+=(--threads "$RTGI_THREADS")
fi
options+=("${user_options[@]}")

# A signal to this script (Slurm's --signal=B:..., Kubernetes stopping the
# pod, Ctrl-C) goes on to rtgi, which saves its checkpoint and stops. When
# rtgi gets the signal itself as well, it takes the two as one request.
child=
forward() {
    if [ -n "$child" ]; then
        kill -s "$1" "$child" 2>/dev/null || true
    fi
}
trap 'forward TERM' TERM
trap 'forward INT' INT

# (The log does not exist before a part's first run: no lines yet.)
first_line=$(($({ wc -l <"$log"; } 2>/dev/null || echo 0) + 1))
echo "== $(date -u +%Y-%m-%dT%H:%M:%SZ) job $index of $count${SLURM_JOB_ID:+ (Slurm job $SLURM_JOB_ID)} on $(hostname): $what" >>"$log"
"$rtgi" "${options[@]}" >>"$log" 2>&1 &
child=$!
while :; do
    status=0
    wait "$child" || status=$?
    # A trapped signal interrupts 'wait' (status above 128) while rtgi is
    # still saving: wait for it again.
    if [ "$status" -gt 128 ] && kill -0 "$child" 2>/dev/null; then
        continue
    fi
    break
done
tail -n "+$first_line" "$log"

case $status in
    0) ;;
    130 | 143)
        fail "$status" "job $index stopped by a signal (exit $status) with its checkpoint saved; run it again" \
            "to resume from $checkpoint"
        ;;
    3)
        fail 3 "$PARTS holds a part or checkpoint of another render (the differences are named above)." \
            "Give this render a folder of its own (PARTS=...), or clear this one: rm -r '$PARTS'"
        ;;
    2)
        fail 2 "rtgi refused its options (see above); fix RTGI_ARGS, SCENE or SPP: running again cannot help"
        ;;
    *)
        fail 1 "rtgi failed (exit $status; see above, or $log); fix the cause: running the job again" \
            "cannot help until then"
        ;;
esac
if tail -n "+$first_line" "$log" | grep -q '^stopped'; then
    # The time limit came first: the checkpoint holds the samples done.
    rm -f "$unfinished"
    fail 75 "job $index reached its time limit; run it again to resume from $checkpoint"
fi
mv "$unfinished" "$part"
rm -f "$checkpoint"
if [ "$what" = "checking $part, done by an earlier run" ]; then
    echo "$0: $part is already done, and is of this render"
else
    echo "$0: wrote $part (samples $from..$to of $SPP)"
fi
