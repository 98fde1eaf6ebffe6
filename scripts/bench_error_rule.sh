#!/usr/bin/env bash
# The error rule of adaptive resolution against full resolution and the size rule alone,
# on shared volumes and their trilinear copies, 1600x1200, front view, warm (--warm-up), 2 threads:
# the defaults first, then the gaps order (--order gaps) alone and with each rule.
# For each run: time to C = 99% (against the engine's own final image), time to 99% of final
# pixels and the triangles then, every ray, and the final image against the full surface.
# Usage: scripts/bench_error_rule.sh [BUILD=build] [DATA=../shared/data] [COPIES=build/data]
# Copies at 2x and 4x are made once by scripts/resample_volume.py (0.5 G voxels at most).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build} data=${2:-../shared/data} copies=${3:-build/data}
[ -d "$data" ] || { echo "bench_error_rule: no data folder $data" >&2; exit 1; }
isowall="$build/bin/isowall"
copy() {  # NAME SCALE -> the copy's header
    local out="$copies/$1_x$2.nhdr"
    [ -f "$out" ] || /usr/bin/python3 scripts/resample_volume.py --scale "$2" --out-dir "$copies" \
        --name "$1_x$2" "$data/$1.nhdr" >&2
    echo "$out"
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
configs=("" "--order gaps" "--order gaps --adaptive --adaptive-pixels 4 --facing-only --adaptive-error 0.5"
         "--order gaps --adaptive --adaptive-pixels 2.5 --no-adaptive-refine --facing-only")
names=("defaults" "full resolution, gaps" "error rule, 4 px, facing" "size rule 2.5 px, no refine, facing")
printf '| volume | iso | engine | C=99%% s | final px 99%% s | triangles then | every ray s | C vs full | final px vs full |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for spec in "engine 75 1" "engine 75 2" "engine 75 4" "cthead 600 1" "cthead 600 2" "heptane 50 1" \
            "heptane 50 2" "vhp_ct_head 40 1" "tooth 620 1"; do
    set -- $spec
    vol="$data/$1.nhdr"
    [ "$3" = 1 ] || vol=$(copy "$1" "$3")
    for i in "${!configs[@]}"; do
        # shellcheck disable=SC2086
        out=$("$isowall" render -v "$vol" --iso "$2" --size 1600x1200 --out "$tmp/image.png" -q --warm-up \
              --threads 2 --against-full ${configs[$i]} 2>&1 | sed -n '/replayed against the final/,/all rays/p;/^against the full/p') || true
        c99=$(awk '/C=1-E >= 99%/ {print $4; exit}' <<<"$out")
        fp=$(awk '/final px >= 99% / {print $5, $8; exit}' <<<"$out")
        end=$(awk '/all rays/ {print $3; exit}' <<<"$out")
        full=$(sed -n 's/^against the full.*: C = \([0-9.]*\), final px \([0-9.]*\)%.*/\1 \2%/p' <<<"$out")
        printf '| %s %sx | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$1" "$3" "$2" "${names[$i]}" \
            "$c99" "${fp% *}" "${fp#* }" "$end" "${full% *}" "${full#* }"
    done
done
