#!/usr/bin/env bash
# Submits a split render to Slurm: a job array whose tasks each render a share
# of every pixel's samples, and the merge that runs once they have all ended.
#
#   deploy/slurm/submit.sh [OPTIONS] TASKS SCENE SPP OUTPUT [rtgi render options...]
#   deploy/slurm/submit.sh --cpus 8 16 scenes/cornell-box.toml 4096 cornell.exr --width 1024 --height 1024
#
# Options (before TASKS):
#   --cpus N          CPUs per task, which rtgi uses as its threads [default: 1]
#   --mem SIZE        memory per task, as sbatch --mem takes it [default: 4G]
#   --time LIMIT      time limit per task, as sbatch --time takes it [default: 01:00:00];
#                     rtgi saves its checkpoint 2 minutes before it
#   --partition NAME  the partition of both jobs [default: the cluster's default]
#   --sbatch OPTION   any other sbatch option for both jobs, once per option
#                     (--sbatch --account=lab --sbatch --qos=long)
#   --only LIST       submit only these tasks of the TASKS (3,7 or 2-5), to redo failed ones;
#                     the merge then runs again too
# Environment:
#   PARTS   folder for the parts, checkpoints and logs [default: ./parts-<OUTPUT's name>]
#   RTGI    the rtgi binary on the compute nodes [default: rtgi on their PATH]
#   SBATCH_PARTITION, SBATCH_TIMELIMIT, ... are read by sbatch itself, as always
# Logs: $PARTS/logs/render-JOB_TASK.log (Slurm's), $PARTS/logs/part-TASK.log (rtgi's,
# every run appended) and $PARTS/logs/merge-JOB.log.
#
# The render's options are every job's; --threads, --spp, -o, --samples, --tile,
# --checkpoint, --resume and --time-limit are this script's own and refused.
# PARTS belongs to one render: submitting another render to it is refused.
set -euo pipefail

usage() {
    sed -n '2,29p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}
fail() {
    echo "submit.sh: $*" >&2
    exit 2
}

here=$(cd "$(dirname "$0")/.." && pwd)
cpus=1 mem=4G time=01:00:00 partition='' only=''
sbatch_options=()
while [ $# -gt 0 ]; do
    case $1 in
        --cpus) cpus=${2:?--cpus takes a number} && shift 2 ;;
        --mem) mem=${2:?--mem takes a size} && shift 2 ;;
        --time) time=${2:?--time takes a time limit} && shift 2 ;;
        --partition) partition=${2:?--partition takes a name} && shift 2 ;;
        --sbatch) sbatch_options+=("${2:?--sbatch takes an sbatch option}") && shift 2 ;;
        --only) only=${2:?--only takes a list of tasks} && shift 2 ;;
        -h | --help) usage ;;
        --*) fail "unknown option $1 (options come before TASKS; see --help)" ;;
        *) break ;;
    esac
done
[ $# -ge 4 ] || usage
tasks=$1 scene=$2 spp=$3 output=$4
shift 4
render_options=("$@")

is_count() { [[ $1 =~ ^[0-9]+$ ]] && [ "$1" -gt 0 ]; }
is_count "$tasks" || fail "TASKS '$tasks' is not a whole number above 0"
is_count "$spp" || fail "SPP '$spp' is not a whole number above 0"
[ "$tasks" -le "$spp" ] || fail "$tasks tasks for $spp samples per pixel: some tasks would have no samples"
is_count "$cpus" || fail "--cpus '$cpus' is not a whole number above 0"
[ -f "$scene" ] || fail "the scene $scene does not exist"
case $output in
    *.png | *.exr) ;;
    *) fail "OUTPUT $output is not an image (.png or .exr)" ;;
esac
output_dir=$(dirname "$output")
if ! [ -d "$output_dir" ] || ! [ -w "$output_dir" ]; then fail "cannot write OUTPUT into $output_dir"; fi
# Jobs run in this folder, but absolute paths survive a cd in a user's options.
scene=$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")
output=$(cd "$output_dir" && pwd)/$(basename "$output")
for option in "${render_options[@]}"; do
    case $option in
        --threads | --threads=* | -t | -t[0-9]*) fail "$option: the threads are the task's CPUs; give --cpus N before TASKS" ;;
        --spp | --spp=*) fail "$option: the samples per pixel are SPP, the third argument" ;;
        -o | --output | --output=*) fail "$option: the image is OUTPUT, the fourth argument" ;;
        --samples | --samples=* | --tile | --tile=* | --checkpoint | --checkpoint=* | --resume | --resume=* | \
            --time-limit | --time-limit=*)
            fail "$option is set by the job script for each task; leave it out (--time LIMIT sets the time)"
            ;;
    esac
done
if [ -n "$only" ]; then
    [[ $only =~ ^[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*$ ]] || fail "--only $only is not a list like 3,7 or 2-5"
    for range in ${only//,/ }; do
        [ "${range#*-}" -lt "$tasks" ] || fail "--only $only: the tasks are 0..$((tasks - 1))"
    done
fi
command -v sbatch >/dev/null 2>&1 || fail "sbatch is not on the PATH: run this on a Slurm submit host"
if ! command -v "${RTGI:-rtgi}" >/dev/null 2>&1; then
    echo "submit.sh: note: ${RTGI:-rtgi} is not on this host's PATH; the compute nodes must have it (or set RTGI)" >&2
fi
# A task asking for more CPUs than any node has would pend forever.
if command -v sinfo >/dev/null 2>&1; then
    most=$( (sinfo -h -o '%c' ${partition:+--partition "$partition"} 2>/dev/null || true) | tr -d '+' | sort -n | tail -1)
    if [ -n "$most" ] && [ "$most" -lt "$cpus" ]; then
        fail "--cpus $cpus: no node${partition:+ of partition $partition} has more than $most CPUs"
    fi
fi

parts=${PARTS:-$PWD/parts-$(basename "${output%.*}")}
mkdir -p "$parts/logs"
parts=$(cd "$parts" && pwd)
# What this render is, to refuse another render in the same folder now
# rather than task by task (rtgi checks each part's identity as well).
render="TASKS=$tasks SCENE=$scene SPP=$spp OUTPUT=$output OPTIONS=${render_options[*]}"
if [ -f "$parts/render" ] && [ "$(cat "$parts/render")" != "$render" ]; then
    fail "$parts holds the parts of another render ($(cat "$parts/render")); give this one a folder of its own" \
        "(PARTS=...), or clear that one: rm -r '$parts'"
fi
echo "$render" >"$parts/render"
# The command that redoes some tasks, for the merge's message.
printf '%q --only ONLY' "$here/slurm/submit.sh" >"$parts/submit-command"
for word in --cpus "$cpus" --mem "$mem" --time "$time" ${partition:+--partition "$partition"}; do
    printf ' %q' "$word" >>"$parts/submit-command"
done
for option in "${sbatch_options[@]}"; do
    printf ' --sbatch %q' "$option" >>"$parts/submit-command"
done
printf ' %q' "$tasks" "$scene" "$spp" "$output" "${render_options[@]}" >>"$parts/submit-command"

common=(--parsable --export=ALL ${partition:+--partition "$partition"} "${sbatch_options[@]}")
array=$(SCENE=$scene SPP=$spp PARTS=$parts RTGI_ARGS="${render_options[*]}" ARRAY_COUNT=$tasks DEPLOY_DIR=$here \
    sbatch "${common[@]}" --array="${only:-0-$((tasks - 1))}" --cpus-per-task="$cpus" --mem="$mem" \
    --time="$time" --output="$parts/logs/render-%A_%a.log" "$here/slurm/render.sbatch")
array=${array%%;*}
merge=$(PARTS=$parts OUTPUT=$output ARRAY_COUNT=$tasks \
    sbatch "${common[@]}" --dependency=afterany:"$array" --kill-on-invalid-dep=yes \
    --output="$parts/logs/merge-%j.log" "$here/slurm/merge.sbatch")
merge=${merge%%;*}
echo "render array $array (tasks ${only:-0-$((tasks - 1))} of $tasks), merge $merge once they end"
echo "parts and logs in $parts; the image will be $output"
