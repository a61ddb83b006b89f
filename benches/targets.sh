#!/usr/bin/env bash
# Measures issue 24's performance targets in one run and writes the table,
# with every run it is made of, to docs/targets.md (or --out FILE):
#
#   benches/targets.sh [--out FILE] [--runs N] [--baseline COMMIT]
#
# - the bunny and the conference room against Embree: the `peers` example
#   (camera rays one at a time and in batches of 16, incoherent rays, the
#   wide build), 2 threads, its medians of 15 alternating runs; skipped, with
#   a message, where Embree 3 is not installed (apt install libembree-dev);
# - cut-outs: the voxel world of tests/tests/render/cutouts.rs, rendered and traced with
#   the alpha test and with it off (--effects=-alpha, --no-alpha), in turn;
# - interiors: default renders of Sponza and the conference room against
#   the build the issue measured (--baseline, 90894cd), by
#   benches/against-baseline.sh;
# - the Cornell box path traced at 256x256, 1024 spp, depth 64.
#
# It takes about 15 minutes on 2 cores; run it on an otherwise idle machine.
# tests/tests/workspace/targets_doc.rs checks that the table agrees with the runs.
set -euo pipefail
cd "$(dirname "$0")/.."

out=docs/targets.md
runs=5
baseline=90894cd
while [[ $# -gt 0 ]]; do
    case "$1" in
        --out) out="${2:?--out needs a file}"; shift 2 ;;
        --runs) runs="${2:?--runs needs a number}"; shift 2 ;;
        --baseline) baseline="${2:?--baseline needs a commit}"; shift 2 ;;
        *) echo "usage: benches/targets.sh [--out FILE] [--runs N] [--baseline COMMIT]" >&2; exit 2 ;;
    esac
done
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "targets: --runs needs a whole number of at least 1, not '$runs'" >&2; exit 2; }

shared="${RTGI_SCENES:-$PWD/../shared/scenes}"
bunny="$shared/bunny/stanford-bunny.obj"
conference="$shared/conference/conference.obj"
sponza="$shared/sponza-dabrovic/sponza.obj"
cornell="$shared/cornell-box/CornellBox-Original.obj"
for scene in "$bunny" "$conference" "$sponza" "$cornell"; do
    [[ -f "$scene" ]] || { echo "targets: no scene at $scene (set RTGI_SCENES)" >&2; exit 1; }
done

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
started="$(date -u +%Y-%m-%dT%H:%M:%SZ)"

echo "building rtgi and the voxel world's writer ..." >&2
cargo build --release --quiet -p rtgi
cargo build --release --quiet -p rtgi-tests --example voxel-world
rtgi=target/release/rtgi
embree=yes
if [[ -f /usr/include/embree3/rtcore.h ]] || pkg-config --exists embree3 2>/dev/null; then
    echo "building the peers example with Embree ..." >&2
    cargo build --release --quiet -p rtgi-benches --example peers --features embree
else
    embree=no
    echo "targets: Embree 3 is not installed (apt install libembree-dev): the rows against Embree are skipped" >&2
fi

rows=()      # table rows, "|"-separated, in order
run_lines=() # "ID ours: V V V against: V V V"

# Two decimals, rounded in double precision as tests/tests/workspace/targets_doc.rs
# rounds (bash's printf rounds in long double: 3.205 became 3.20, not 3.21).
two_places() {
    awk -v v="$1" 'BEGIN { printf "%.2f", v }'
}

median() { # of the numbers given as arguments
    printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}

# row ID SCENE MEASURE AGAINST-LABEL TARGET "OURS..." "AGAINST..."
# TARGET is "ratio>=X" or "ratio<=X" (ours / against) or "ours>=X", or
# "none" for a row that is there for comparison only; an empty AGAINST
# list has no ratio.
row() {
    local id="$1" scene="$2" measure="$3" label="$4" target="$5" ours=($6) against=(${7:-})
    local m_ours m_against ratio="—" against_cell="—" goal met="" value op bound
    m_ours="$(median "${ours[@]}")"
    if [[ ${#against[@]} -gt 0 ]]; then
        m_against="$(median "${against[@]}")"
        ratio="$(awk -v a="$m_ours" -v b="$m_against" 'BEGIN { printf "%.2f×", a / b }')"
        against_cell="$(two_places "$m_against") ($label)"
    fi
    case "$target" in
        ratio\>=*) value="${ratio%×}"; op=">="; bound="${target#ratio>=}"; goal="≥ ${bound}×" ;;
        ratio\<=*) value="${ratio%×}"; op="<="; bound="${target#ratio<=}"; goal="≤ ${bound}×" ;;
        ours\>=*) value="$(two_places "$m_ours")"; op=">="; bound="${target#ours>=}"; goal="≥ $bound" ;;
        none) goal="—"; met="—" ;;
        *) echo "targets: unknown target '$target'" >&2; exit 1 ;;
    esac
    [[ -n "$met" ]] ||
        met="$(awk -v v="$value" -v b="$bound" -v op="$op" 'BEGIN { ok = op == ">=" ? v >= b : v <= b; print ok ? "**met**" : "no" }')"
    rows+=("| $id | $scene | $measure | $(two_places "$m_ours") | $against_cell | $ratio | $goal | $met |")
    run_lines+=("$id ours: ${ours[*]} against: ${against[*]}")
}

# The value in the 2-thread row of a section of peers' output, in the
# column named NAME, by its place on peers' "columns:" line.
peers_value() { # FILE SECTION NAME
    awk -v section="$2" -v name="$3" '
        /^columns: / { n = split(substr($0, 10), names, ", "); for (i = 1; i <= n; i++) if (names[i] == name) column = i }
        $0 == section { inside = 1; next }
        inside && $1 == "2" { if (column) print $column; exit }
    ' "$1"
}

if [[ "$embree" == yes ]]; then
    for scene in bunny conference; do
        path="$bunny"
        [[ "$scene" == conference ]] && path="$conference"
        echo "peers on the $scene (about 3 minutes) ..." >&2
        target/release/examples/peers "$path" >"$scratch/peers-$scene.txt"
        value() {
            local v
            v="$(peers_value "$scratch/peers-$scene.txt" "$1" "$2")"
            [[ -n "$v" ]] || { echo "targets: no '$2' in the '$1' section of peers' output:" >&2; cat "$scratch/peers-$scene.txt" >&2; exit 1; }
            echo "$v"
        }
        row "$scene-camera" "$scene" "camera rays, single-ray API, Mrays/s (bvh8)" "Embree rtcIntersect1" "ratio>=1.2" \
            "$(value "primary Mrays/s" "rtgi bvh8")" "$(value "primary Mrays/s" "embree 1")"
        row "$scene-batch" "$scene" "camera rays, batch API, Mrays/s (bvh8)" "Embree rtcIntersect16" "ratio>=1.0" \
            "$(value "primary Mrays/s" "rtgi bvh8 16")" "$(value "primary Mrays/s" "embree 16")"
        row "$scene-incoherent" "$scene" "incoherent rays, Mrays/s (bvh8)" "Embree rtcIntersect1" "ratio>=1.0" \
            "$(value "incoherent Mrays/s" "rtgi bvh8")" "$(value "incoherent Mrays/s" "embree 1")"
        # Like with like: Embree with RTC_SCENE_FLAG_ROBUST, its watertight
        # triangle test and conservative traversal, as ours always are.
        row "$scene-camera-robust" "$scene" "camera rays, single-ray API, Mrays/s (bvh8)" "Embree rtcIntersect1, robust scene" "none" \
            "$(value "primary Mrays/s" "rtgi bvh8")" "$(value "primary Mrays/s" "embree robust 1")"
        row "$scene-incoherent-robust" "$scene" "incoherent rays, Mrays/s (bvh8)" "Embree rtcIntersect1, robust scene" "none" \
            "$(value "incoherent Mrays/s" "rtgi bvh8")" "$(value "incoherent Mrays/s" "embree robust 1")"
        row "$scene-build" "$scene" "wide build, ms (bvh8)" "Embree" "ratio<=1.0" \
            "$(value "build ms" "rtgi bvh8")" "$(value "build ms" "embree 1")"
    done
fi

# The milliseconds on a line of rtgi's output that starts with WORD.
milliseconds() { # WORD OUTPUT
    sed -n "s/^$1 *\([0-9.]*\) ms.*/\1/p" <<<"$2" | head -n 1
}
# Runs rtgi with ARGS and prints its output (stderr included); a run that
# fails stops the script with its last lines.
run_rtgi() {
    local output
    output="$("$rtgi" "$@" 2>&1)" || {
        echo "targets: 'rtgi $*' failed:" >&2
        tail -n 5 <<<"$output" >&2
        exit 1
    }
    echo "$output"
}
timed() { # WORD ARGS... : runs rtgi, prints the milliseconds of its WORD line
    local word="$1" output ms
    shift
    output="$(run_rtgi "$@")" || exit 1
    ms="$(milliseconds "$word" "$output")"
    [[ -n "$ms" ]] || {
        echo "targets: 'rtgi $*' gave no '$word' time:" >&2
        tail -n 5 <<<"$output" >&2
        exit 1
    }
    echo "$ms"
}

echo "cut-outs: the voxel world ..." >&2
world="$(target/release/examples/voxel-world "$scratch/world" 48)"
view=(--at -6,16,-6 --look 20,4,20)
run_rtgi rays "$world" "${view[@]}" --kind camera --width 1024 --height 768 -o "$scratch/camera.rays" >/dev/null
run_rtgi rays "$world" "${view[@]}" --kind surface --count 1000000 -o "$scratch/surface.rays" >/dev/null
render=(render "$world" "${view[@]}" --width 320 --height 240 --spp 16 -t 2 -o "$scratch/world.exr")
run_rtgi "${render[@]}" >/dev/null # the first run reads the files into the cache
with=() without=()
for _ in $(seq "$runs"); do
    with+=("$(timed render "${render[@]}")")
    without+=("$(timed render "${render[@]}" --effects=-alpha)")
done
row cut-outs-render "voxel world" "render, 320x240 at 16 spp, ms" "alpha off" "ratio<=1.5" "${with[*]}" "${without[*]}"
for kind in camera surface; do
    with=() without=()
    for _ in $(seq "$runs"); do
        with+=("$(timed trace trace "$world" --rays "$scratch/$kind.rays" -o "$scratch/hits.bin" -t 2)")
        without+=("$(timed trace trace "$world" --rays "$scratch/$kind.rays" -o "$scratch/hits.bin" -t 2 --no-alpha)")
    done
    row "cut-outs-trace-$kind" "voxel world" "rtgi trace, $kind rays, ms" "alpha off" "ratio<=1.5" "${with[*]}" "${without[*]}"
done

echo "interiors against $baseline ..." >&2
benches/against-baseline.sh --runs "$runs" "$baseline" "$sponza" "$conference" -- -t 2 >"$scratch/interiors.txt"
for scene in sponza conference; do
    line="$(grep "^runs $scene.obj " "$scratch/interiors.txt")" || { cat "$scratch/interiors.txt" >&2; exit 1; }
    old="$(sed 's/.* old: \(.*\) new: .*/\1/' <<<"$line")"
    new="$(sed 's/.* new: //' <<<"$line")"
    row "interiors-$scene" "$scene" "default render (512x512, 16 spp), Mrays/s" "$(git rev-parse --short "$baseline")" "ratio>=1.5" "$new" "$old"
done

echo "the Cornell box ..." >&2
samples=()
for _ in $(seq 3); do
    ms="$(timed render render "$cornell" --width 256 --height 256 --spp 1024 --max-depth 64 -t 2 -o "$scratch/cornell.exr")"
    samples+=("$(awk -v ms="$ms" 'BEGIN { printf "%.4f", 256 * 256 * 1024 / (ms / 1000) / 1e6 }')")
done
row cornell "Cornell box" "path tracing, 256x256, 1024 spp, depth 64, M samples/s" "" "ours>=5" "${samples[*]}" ""

commit="$(git rev-parse --short HEAD)"
git diff --quiet HEAD -- crates apps benches || commit="$commit (with uncommitted changes)"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
{
    echo "# Issue 24's performance targets, measured"
    echo
    echo "<!-- written by benches/targets.sh; tests/tests/workspace/targets_doc.rs checks the table against the runs below -->"
    echo "Measured from $started to $(date -u +%Y-%m-%dT%H:%M:%SZ) on ${cpu:-an unknown CPU} ($(nproc) cores), 2 threads, at commit $commit, by \`benches/targets.sh --runs $runs --baseline $baseline\`."
    echo "Figures are medians: of the runs below, and for the rows against Embree of the \`peers\` example's 15 alternating runs, whose medians are the runs listed."
    echo "Rows whose target is — are for comparison only: ours against Embree with \`RTC_SCENE_FLAG_ROBUST\` (a watertight triangle test and a conservative traversal, which ours always has), not one of the issue's targets."
    [[ "$embree" == yes ]] || echo "Embree 3 was not installed, so the rows against it were not measured."
    echo
    echo "| id | scene | measure | ours | against | ours / against | target | met |"
    echo "|---|---|---|---:|---:|---:|---|---|"
    printf '%s\n' "${rows[@]}"
    echo
    echo "## Runs"
    echo
    echo '```text'
    printf '%s\n' "${run_lines[@]}"
    echo '```'
} >"$out"
echo "wrote $out" >&2
cat "$out"
