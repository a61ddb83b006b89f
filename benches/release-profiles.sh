#!/usr/bin/env bash
# Measures the release profile's choices, link-time optimisation (thin,
# fat, off) and codegen units (1, 4, 16), on what each costs and buys:
#
# - the release build of `rtgi` from clean, in a target directory of its own;
# - the rebuild after touching one file of rtgi-render (what a developer
#   waits for after each edit);
# - the bunny's trace (rtgi trace, a million surface rays, 2 threads, Mrays/s);
# - the Cornell box path traced (rtgi render, 256x256, 64 spp, 2 threads,
#   M samples/s).
#
# The rates are measured in one run, the binaries taking turns, so that a
# machine's drift falls on all of them alike; each cell is the median of
# the runs (min-max), and the ratio is to the shipped profile's median.
# Writes docs/release-profiles.md (every run listed under its table, which
# tests/tests/workspace/release_profiles_doc.rs checks), the table's only
# home: the README and the guide link to it.
#
#   benches/release-profiles.sh [--runs N] [LTO:CGU ...]
#   benches/release-profiles.sh --tabulate
#
# --tabulate measures nothing: it writes the table again from the runs
# recorded in docs/release-profiles.md (after a change to how the table is
# made, say), keeping the document's account of when and where they ran.
#
# The default configurations vary one knob at a time around the shipped
# thin:4, and add off:16, the fastest to build. A run takes about 40
# minutes on 2 cores; the builds go to target/profiles/ (removed at the end).
set -euo pipefail
cd "$(dirname "$0")/.."

runs=5
tabulate=no
if [[ "${1:-}" == "--tabulate" ]]; then
    tabulate=yes
    shift
fi
if [[ "${1:-}" == "--runs" ]]; then
    runs="${2:?--runs needs a number}"
    shift 2
fi
configs=("$@")
if [[ ${#configs[@]} -eq 0 ]]; then
    configs=(thin:4 fat:4 off:4 thin:1 thin:16 off:16)
fi
# The profile in Cargo.toml, which every other configuration is compared with.
shipped_lto="$(sed -n '/^\[profile.release\]/,/^\[/s/^lto = "\(.*\)"/\1/p' Cargo.toml)"
shipped_cgu="$(sed -n '/^\[profile.release\]/,/^\[/s/^codegen-units = \([0-9]*\)/\1/p' Cargo.toml)"
shipped="$shipped_lto:$shipped_cgu"
[[ " ${configs[*]} " == *" $shipped "* ]] || configs=("$shipped" "${configs[@]}")

declare -A clean relink trace_runs render_runs
if [[ "$tabulate" == yes ]]; then
    configs=()
    while read -r config _ build_clean build_relink _ rest; do
        configs+=("$config")
        clean[$config]="$build_clean" relink[$config]="$build_relink"
        trace_runs[$config]="${rest%% render: *}" render_runs[$config]="${rest##* render: }"
    done < <(sed -n '/^```text$/,/^```$/{/ build: /p}' docs/release-profiles.md)
    [[ ${#configs[@]} -gt 0 ]] || { echo "release-profiles: no runs in docs/release-profiles.md" >&2; exit 1; }
    runs="$(wc -w <<<"${trace_runs[${configs[0]}]}")"
fi

shared="${RTGI_SCENES:-$PWD/../shared/scenes}"
bunny="$shared/bunny/stanford-bunny.obj"
cornell="$shared/cornell-box/CornellBox-Original.obj"
for scene in "$bunny" "$cornell"; do
    [[ -f "$scene" ]] || { echo "release-profiles: no scene at $scene (set RTGI_SCENES)" >&2; exit 1; }
done
if [[ "$tabulate" == no && -n "$(git status --porcelain -- crates apps Cargo.toml Cargo.lock)" ]]; then
    echo "release-profiles: the sources have uncommitted changes; commit them so that the table names its code" >&2
    exit 1
fi

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
seconds_of() { # COMMAND...: runs it, prints its wall seconds
    local start end
    start="$(date +%s.%N)"
    "$@" >"$scratch/build.log" 2>&1 || { echo "release-profiles: '$*' failed:" >&2; tail -n 20 "$scratch/build.log" >&2; exit 1; }
    end="$(date +%s.%N)"
    awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }'
}
build() { # LTO CGU DIR
    env CARGO_TARGET_DIR="$3" CARGO_PROFILE_RELEASE_LTO="$1" CARGO_PROFILE_RELEASE_CODEGEN_UNITS="$2" \
        cargo build --release --locked --quiet -p rtgi --bin rtgi
}

for config in "${configs[@]}"; do
    [[ "$tabulate" == yes ]] && break
    lto="${config%%:*}" cgu="${config##*:}"
    dir="target/profiles/$lto-$cgu"
    rm -rf "$dir"
    echo "building with lto = $lto, codegen-units = $cgu from clean ..." >&2
    clean[$config]="$(seconds_of build "$lto" "$cgu" "$dir")"
    touch crates/render/src/lib.rs
    relink[$config]="$(seconds_of build "$lto" "$cgu" "$dir")"
    cp "$dir/release/rtgi" "$scratch/rtgi-$lto-$cgu"
    rm -rf "$dir"
    echo "  ${clean[$config]} s from clean, ${relink[$config]} s after touching crates/render/src/lib.rs" >&2
done

[[ "$tabulate" == yes ]] ||
    "$scratch/rtgi-${shipped/:/-}" rays "$bunny" --kind surface --count 1000000 -o "$scratch/bunny.rays" >/dev/null
for ((run = 1; run <= runs; run++)); do
    [[ "$tabulate" == yes ]] && break
    echo "run $run of $runs ..." >&2
    for config in "${configs[@]}"; do
        rtgi="$scratch/rtgi-${config/:/-}"
        out="$("$rtgi" trace "$bunny" --rays "$scratch/bunny.rays" -o "$scratch/hits" -t 2 2>&1)" \
            || { echo "release-profiles: trace failed: $out" >&2; exit 1; }
        rate="$(sed -n 's/.*hits, \([0-9.]*\) Mrays\/s.*/\1/p' <<<"$out")"
        [[ -n "$rate" ]] || { echo "release-profiles: no rate in: $out" >&2; exit 1; }
        trace_runs[$config]+="$rate "
        out="$("$rtgi" render "$cornell" --width 256 --height 256 --spp 64 -t 2 -o "$scratch/cornell.exr" 2>&1)" \
            || { echo "release-profiles: render failed: $out" >&2; exit 1; }
        ms="$(sed -n 's/^render *\([0-9.]*\) ms.*/\1/p' <<<"$out")"
        [[ -n "$ms" ]] || { echo "release-profiles: no render time in: $out" >&2; exit 1; }
        render_runs[$config]+="$(awk -v ms="$ms" 'BEGIN { printf "%.3f", 256 * 256 * 64 / ms / 1e3 }') "
    done
done

median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
cell() { # RUNS...: "median (min-max)", rounded by awk in double precision (bash's printf
    # rounds in long double: 1.675 to 1.67, where a double's 1.675 rounds to 1.68)
    local sorted
    sorted="$(printf '%s\n' "$@" | sort -g)"
    awk -v m="$(median "$@")" -v lo="$(head -n 1 <<<"$sorted")" -v hi="$(tail -n 1 <<<"$sorted")" \
        'BEGIN { printf "%.2f (%.2f–%.2f)", m, lo, hi }'
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f×", a / b }'; }

table="| LTO | codegen units | build from clean, s | rebuild after touching rtgi-render, s | bunny trace, Mrays/s | ratio | Cornell box, M samples/s | ratio |
|---|---:|---:|---:|---:|---:|---:|---:|"
shipped_trace="$(median ${trace_runs[$shipped]})"
shipped_render="$(median ${render_runs[$shipped]})"
for config in "${configs[@]}"; do
    lto="${config%%:*}" cgu="${config##*:}"
    name="$lto"
    [[ "$config" == "$shipped" ]] && name="$lto (shipped)"
    table+="
| $name | $cgu | ${clean[$config]} | ${relink[$config]} | $(cell ${trace_runs[$config]}) | $(ratio "$(median ${trace_runs[$config]})" "$shipped_trace") | $(cell ${render_runs[$config]}) | $(ratio "$(median ${render_runs[$config]})" "$shipped_render") |"
done

commit="$(git rev-parse --short=10 HEAD)"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
if [[ "$tabulate" == yes ]]; then
    # The account of the runs, as measured.
    header="$(sed -n '1,/^| LTO /{/^| LTO /!p}' docs/release-profiles.md)"
else
    header="# The release profile, measured

Written by \`benches/release-profiles.sh\` on $(date -u +%Y-%m-%d) at $commit, on $(nproc) cores of an $cpu,
$runs runs of each rate, the binaries taking turns. Builds are one each, \`cargo build --release -p rtgi\`
in a target directory of its own; a rebuild follows \`touch crates/render/src/lib.rs\`.
Rates are medians (min–max); ratios are to the shipped profile's medians."
fi
{
    echo "$header"
    echo
    echo "$table"
    echo
    echo "Every run (build seconds from clean and after the touch; Mrays/s of the trace; M samples/s of the render):"
    echo
    echo '```text'
    for config in "${configs[@]}"; do
        echo "$config build: ${clean[$config]} ${relink[$config]} trace: ${trace_runs[$config]% } render: ${render_runs[$config]% }"
    done
    echo '```'
} >docs/release-profiles.md

echo "wrote docs/release-profiles.md" >&2
