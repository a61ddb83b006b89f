#!/usr/bin/env bash
# Counts, per ray, what our bvh8 and Embree do on the same rays, one
# thread, through the single-ray queries (`rtgi trace --single-ray`: for
# Embree rtcIntersect1, not its packets), and writes the table with every count it is made of to
# docs/counters.md (or --out FILE):
#
#   benches/counters.sh [--out FILE] [--count N] [--runs N]
#
# This machine (a VM) exposes no hardware performance counters (`perf stat`
# reports cycles, instructions, cache and branch events as "not
# supported"), so the counts come from Valgrind's cachegrind: instructions
# exactly, L1 data and last-level misses from its cache simulation of this
# CPU's caches, and mispredicted branches from its branch predictor model.
# They are counts of the AVX2 kernels on both sides: Valgrind's virtual CPU
# has no AVX-512, and both programs dispatch at run time.
#
# Each ray file R is traced once and as R twice (the file after itself);
# the difference of the two runs' totals is the cost of tracing R once
# more: loading, building and starting up cancel, and what is left is
# traversal plus `rtgi trace`'s own per-ray work (reading a ray, writing a
# hit), the same on both sides and measured alone on rays that miss the
# scene's bounds. Nodes and triangle tests per ray are ours only
# (`rtgi trace --stats`); Embree reports them only from a build with its
# statistics compiled in, which Debian's libembree-dev is not. Time per ray
# is measured natively (AVX-512 where the CPU has it, for both), median of
# --runs alternating runs of R twice.
#
# It takes about 15 minutes on 2 cores; run it on an otherwise idle machine.
# tests/tests/workspace/counters_doc.rs checks the table against the counts.
set -euo pipefail
cd "$(dirname "$0")/.."

out=docs/counters.md
count=100000
runs=5
while [[ $# -gt 0 ]]; do
    case "$1" in
        --out) out="${2:?--out needs a file}"; shift 2 ;;
        --count) count="${2:?--count needs a number}"; shift 2 ;;
        --runs) runs="${2:?--runs needs a number}"; shift 2 ;;
        *) echo "usage: benches/counters.sh [--out FILE] [--count N] [--runs N]" >&2; exit 2 ;;
    esac
done
for n in "$count" "$runs"; do
    [[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "counters: --count and --runs take whole numbers of at least 1, not '$n'" >&2; exit 2; }
done
command -v valgrind >/dev/null || { echo "counters: needs Valgrind (apt install valgrind)" >&2; exit 1; }
[[ -f /usr/include/embree3/rtcore.h ]] || { echo "counters: needs Embree 3 (apt install libembree-dev)" >&2; exit 1; }

shared="${RTGI_SCENES:-$PWD/../shared/scenes}"
bunny="$shared/bunny/stanford-bunny.obj"
conference="$shared/conference/conference.obj"
cornell="$shared/cornell-box/CornellBox-Original.obj"
for scene in "$bunny" "$conference" "$cornell"; do
    [[ -f "$scene" ]] || { echo "counters: no scene at $scene (set RTGI_SCENES)" >&2; exit 1; }
done

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
started="$(date -u +%Y-%m-%dT%H:%M:%SZ)"
echo "building rtgi with Embree ..." >&2
cargo build --release --quiet -p rtgi --features embree
rtgi=target/release/rtgi

run_rtgi() { # ARGS...: runs rtgi, prints its output; a failure stops the script
    local output
    output="$("$rtgi" "$@" 2>&1)" || {
        echo "counters: 'rtgi $*' failed:" >&2
        tail -n 5 <<<"$output" >&2
        exit 1
    }
    echo "$output"
}

# The ray sets: ID SCENE, with the file $scratch/ID.rays.
sets=()
make_rays() { # ID SCENE RTGI-RAYS-ARGS...
    local id="$1" scene="$2"
    shift 2
    run_rtgi rays "$scene" "$@" -o "$scratch/$id.rays" >/dev/null
    cat "$scratch/$id.rays" "$scratch/$id.rays" >"$scratch/$id.twice.rays"
    sets+=("$id $scene")
}
side="$(awk -v n="$count" 'BEGIN { printf "%d", sqrt(n) }')"
make_rays bunny-random "$bunny" --kind random --count "$count"
make_rays bunny-camera "$bunny" --kind camera --width "$side" --height "$side"
make_rays conference-random "$conference" --kind random --count "$count"
# A path tracer's secondary rays in a scene of 36 triangles, where a ray
# tests about one node and one block: what is left is each side's cost per
# ray, not per node (the Cornell box target of issue 50).
make_rays cornell-surface "$cornell" --kind surface --count "$count"
# Rays that miss the bunny's bounds: every query ends at the root, so what
# is left is rtgi trace's own per-ray work.
python3 - "$scratch/bunny-miss.rays" "$count" <<'EOF'
import struct, sys
with open(sys.argv[1], "wb") as f:
    for i in range(int(sys.argv[2])):
        f.write(struct.pack("<8f", 1e4, 1e4 + i * 1e-3, 1e4, 1.0, 0.0, 0.0, 0.0, float("inf")))
EOF
cat "$scratch/bunny-miss.rays" "$scratch/bunny-miss.rays" >"$scratch/bunny-miss.twice.rays"
sets+=("bunny-miss $bunny")

# The totals of a cachegrind run of `rtgi trace`: Ir, L1D misses, LL data
# misses, mispredicted branches (conditional and indirect).
grind() { # ACCEL SCENE RAYS
    local file="$scratch/cachegrind.out"
    valgrind --tool=cachegrind --cache-sim=yes --branch-sim=yes --cachegrind-out-file="$file" \
        "$rtgi" trace "$2" --rays "$3" -o "$scratch/hits.bin" -t 1 --accel "$1" --single-ray >/dev/null 2>"$scratch/valgrind.log" || {
        echo "counters: valgrind on 'rtgi trace $2 --accel $1' failed:" >&2
        tail -n 5 "$scratch/valgrind.log" >&2
        exit 1
    }
    awk '
        /^events: / { for (i = 2; i <= NF; i++) column[$i] = i }
        /^summary: / {
            printf "%.0f %.0f %.0f %.0f\n", $column["Ir"], $column["D1mr"] + $column["D1mw"], \
                $column["DLmr"] + $column["DLmw"], $column["Bcm"] + $column["Bim"]
        }
    ' "$file"
}

# The kernels Valgrind's virtual CPU runs ours at (Embree dispatches alike).
grind_level="$(valgrind --tool=none "$rtgi" trace "$bunny" --rays "$scratch/bunny-miss.rays" -o "$scratch/hits.bin" -t 1 --stats 2>&1 |
    sed -n 's/^stats .*; \([a-z0-9]*\) kernels)$/\1/p')"
[[ -n "$grind_level" ]] || { echo "counters: rtgi trace --stats under Valgrind named no kernels" >&2; exit 1; }

lines=() # "ID ACCEL rays: N once: ... twice: ... ns: ... work: NODES TESTS"
for set in "${sets[@]}"; do
    read -r id scene <<<"$set"
    rays_in=$(($(stat -c %s "$scratch/$id.rays") / 32))
    for accel in bvh8 embree; do
        echo "cachegrind: $id, $accel ..." >&2
        once="$(grind "$accel" "$scene" "$scratch/$id.rays")"
        twice="$(grind "$accel" "$scene" "$scratch/$id.twice.rays")"
        work="— —"
        if [[ "$accel" != embree ]]; then
            stats="$(run_rtgi trace "$scene" --rays "$scratch/$id.rays" -o "$scratch/hits.bin" -t 1 --accel "$accel" --stats)"
            work="$(sed -n 's/^stats *\([0-9.]*\) nodes, \([0-9.]*\) triangle tests per ray.*/\1 \2/p' <<<"$stats")"
            [[ -n "$work" ]] || { echo "counters: no counts in: $stats" >&2; exit 1; }
        fi
        lines+=("$id $accel rays: $rays_in once: $once twice: $twice work: $work")
    done
    # Native time, the two structures in turn.
    declare -A ns=()
    for _ in $(seq "$runs"); do
        for accel in bvh8 embree; do
            output="$(run_rtgi trace "$scene" --rays "$scratch/$id.twice.rays" -o "$scratch/hits.bin" -t 1 --accel "$accel" --single-ray)"
            ms="$(sed -n 's/^trace *\([0-9.]*\) ms:.*/\1/p' <<<"$output")"
            ns[$accel]+="$(awk -v ms="$ms" -v n="$((2 * rays_in))" 'BEGIN { printf "%.2f", ms * 1e6 / n }') "
        done
    done
    for i in "${!lines[@]}"; do
        read -r line_id line_accel _ <<<"${lines[$i]}"
        [[ "$line_id" == "$id" ]] && lines[i]="${lines[$i]} ns: ${ns[$line_accel]% }"
    done
    unset ns
done

per_ray() { # TOTAL-ONCE TOTAL-TWICE RAYS
    # (0.0, not -0.0, where a count falls by less than half a tenth a ray)
    awk -v a="$1" -v b="$2" -v n="$3" 'BEGIN { v = (b - a) / n; if (v > -0.05 && v < 0.05) v = 0; printf "%.1f", v }'
}
median() {
    printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}
rows=()
for line in "${lines[@]}"; do
    read -r id accel _ rays _ o1 o2 o3 o4 _ t1 t2 t3 t4 _ nodes tests _ times <<<"$line"
    ir="$(per_ray "$o1" "$t1" "$rays")"
    per_node="—"
    [[ "$nodes" != "—" ]] && per_node="$(awk -v i="$ir" -v n="$nodes" 'BEGIN { printf "%.1f", i / n }')"
    # shellcheck disable=SC2086
    rows+=("| $id | $accel | $ir | $(per_ray "$o2" "$t2" "$rays") | $(per_ray "$o3" "$t3" "$rays") | $(per_ray "$o4" "$t4" "$rays") | $(median $times) | $nodes | $tests | $per_node |")
done

commit="$(git rev-parse --short HEAD)"
git diff --quiet HEAD -- crates apps benches || commit="$commit (with uncommitted changes)"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
{
    echo "# What a ray costs: our bvh8 and Embree, counted on the same rays"
    echo
    echo "<!-- written by benches/counters.sh; tests/tests/workspace/counters_doc.rs checks the table against the counts below -->"
    echo "Measured from $started to $(date -u +%Y-%m-%dT%H:%M:%SZ) on ${cpu:-an unknown CPU}, 1 thread, at commit $commit, with $(valgrind --version) and Embree $(dpkg-query -W -f='${Version}' libembree3-3 2>/dev/null || echo "(version unknown)"), by \`benches/counters.sh --count $count --runs $runs\`."
    echo
    echo "This machine exposes no hardware performance counters, so cycles, and the IPC that needs them, are not counted here."
    echo "Instructions are counted exactly by Valgrind's cachegrind; L1 data and last-level misses come from its simulation of this CPU's caches, and mispredicted branches from its predictor model: under Valgrind ours ran its $grind_level kernels (Valgrind's virtual CPU has no AVX-512), and Embree dispatches at run time alike."
    echo "Each figure per ray is the difference between tracing the rays once and twice in one process, divided by the rays, so loading, building and start-up cancel."
    echo "It includes \`rtgi trace\`'s own per-ray work (reading a ray, writing a hit), the same for both; the bunny-miss rows, rays that miss the scene's bounds, measure it alone."
    echo "Both trace ray by ray through the single-ray query (\`rtgi trace --single-ray\`; for Embree \`rtcIntersect1\`), the node step docs/node-cost.md reads side by side."
    echo "Time per ray is native (AVX-512 kernels where the CPU has them, on both sides), the median of the runs listed."
    echo "Nodes and triangle tests are counted by \`rtgi trace --stats\`; Embree reports them only from a build with its statistics compiled in, which Debian's is not."
    echo
    echo "| rays | structure | instructions / ray | L1D misses / ray | LL misses / ray | mispredicted branches / ray | ns / ray (native) | nodes / ray | triangle tests / ray | instructions / node |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    printf '%s\n' "${rows[@]}"
    echo
    echo "The counts (cachegrind totals: instructions, L1D misses, LL misses, mispredicted branches; native ns per ray; nodes and triangle tests per ray):"
    echo
    echo '```text'
    printf '%s\n' "${lines[@]}"
    echo '```'
} >"$out"
echo "wrote $out" >&2
