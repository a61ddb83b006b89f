#!/usr/bin/env bash
# Renders scenes with this checkout's `rtgi` and with an older commit's, in
# one run, the two binaries taking turns, and prints the rays per second
# each render reports: median (min-max) and the ratio new / old, then
# every run's rate ("runs SCENE old: R R R new: R R R"). This is
# how an issue's "N times today's rate" is measured, since timings on a
# shared machine drift between runs that are not interleaved.
#
#   benches/against-baseline.sh [--runs N] COMMIT [SCENE...] [-- RENDER-OPTIONS...]
#
# SCENE defaults to Sponza and the conference room of the shared scenes
# ($RTGI_SCENES, or ../shared/scenes beside the workspace); RENDER-OPTIONS
# are passed to both renders (the defaults: `rtgi render SCENE`, 512x512 at
# 16 spp). The old commit is built in a git worktree under
# target/baseline/ (its own target directory; the first build takes minutes),
# which stays for the next run: `git worktree remove target/baseline/HASH`
# deletes it.
set -euo pipefail
cd "$(dirname "$0")/.."

runs=3
if [[ "${1:-}" == "--runs" ]]; then
    runs="${2:?--runs needs a number}"
    shift 2
fi
commit="${1:?usage: benches/against-baseline.sh [--runs N] COMMIT [SCENE...] [-- RENDER-OPTIONS...]}"
shift
scenes=()
while [[ $# -gt 0 && "$1" != "--" ]]; do
    scenes+=("$1")
    shift
done
[[ "${1:-}" == "--" ]] && shift
options=("$@")

shared="${RTGI_SCENES:-$PWD/../shared/scenes}"
if [[ ${#scenes[@]} -eq 0 ]]; then
    scenes=("$shared/sponza-dabrovic/sponza.obj" "$shared/conference/conference.obj")
fi
for scene in "${scenes[@]}"; do
    [[ -f "$scene" ]] || { echo "against-baseline: no scene at $scene (set RTGI_SCENES or name the scenes)" >&2; exit 1; }
done

hash="$(git rev-parse --verify --quiet --short "$commit^{commit}")" || {
    echo "against-baseline: '$commit' is not a commit of this repository" >&2
    exit 1
}
worktree="target/baseline/$hash"
if [[ ! -d "$worktree" ]]; then
    git worktree add --detach "$worktree" "$hash" >/dev/null
fi
echo "building $hash (old) in $worktree and this checkout (new) ..." >&2
(cd "$worktree" && cargo build --release --quiet -p rtgi)
cargo build --release --quiet -p rtgi
old="$worktree/target/release/rtgi"
new="target/release/rtgi"

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

# The rate a render reports on its "rays" line: "rays  N (R Mrays/s)"; a
# render that fails or prints no rate stops the run with its last lines.
rate() {
    local output value
    output="$("$1" render "$2" -o "$scratch/image.exr" "${options[@]}" 2>&1)" &&
        value="$(sed -n 's/^rays .*(\([0-9.]*\) Mrays\/s).*/\1/p' <<<"$output")" && [[ -n "$value" ]] || {
        echo "against-baseline: '$1 render $2' gave no rate:" >&2
        tail -n 5 <<<"$output" >&2
        exit 1
    }
    echo "$value"
}

summary() { # median (min-max) of the numbers on standard input
    sort -g | awk '{ v[NR] = $1 } END { printf "%s (%s-%s)", v[int((NR + 1) / 2)], v[1], v[NR] }'
}

runs_lines=()
printf '%-40s %-24s %-24s %s\n' "scene (Mrays/s, $runs runs)" "old $hash" "new $(git rev-parse --short HEAD)" "new / old"
for scene in "${scenes[@]}"; do
    : >"$scratch/old" && : >"$scratch/new"
    for _ in $(seq "$runs"); do
        rate "$old" "$scene" >>"$scratch/old"
        rate "$new" "$scene" >>"$scratch/new"
    done
    old_summary="$(summary <"$scratch/old")"
    new_summary="$(summary <"$scratch/new")"
    # The medians are the summaries' first words.
    ratio="$(awk -v n="${new_summary%% *}" -v o="${old_summary%% *}" 'BEGIN { printf "%.2fx", n / o }')"
    printf '%-40s %-24s %-24s %s\n' "$(basename "$scene")" "$old_summary" "$new_summary" "$ratio"
    runs_lines+=("runs $(basename "$scene") old: $(tr '\n' ' ' <"$scratch/old")new: $(tr '\n' ' ' <"$scratch/new")")
done
printf '%s\n' "${runs_lines[@]}"
