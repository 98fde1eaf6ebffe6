#!/usr/bin/env bash
# Emulates a display wall on this machine: one master rank plus one rank per tile of the wall file
# (two with stereo), oversubscribed, writing the stitched mosaic. ISOWALL_RECOVERY=1 keeps the wall
# going when a tile rank dies (exit 3 then). Usage: scripts/wall_demo.sh [WALL.toml] [isowall wall options]
# (default walls/2x2.toml on the built-in phantom; e.g. walls/6x4.toml -v ../shared/data/vhp_ct_head.nhdr --iso 40)
set -euo pipefail
cd "$(dirname "$0")/.."
WALL=${1:-walls/2x2.toml}
shift || true
[ -x build/bin/isowall ] || bash scripts/setup.sh
# Open MPI refuses root and more ranks than cores unless told; a one-machine emulation needs both.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
NP=$(./build/bin/isowall wall --wall "$WALL" --ranks-needed)
mkdir -p out
# llvmpipe rasterises in the calling thread, so each rank's thread CPU counts its drawing too: the
# per-rank table then says what each rank would cost on a node of its own.
if [ "${ISOWALL_RECOVERY:-0}" != 1 ]; then
    exec mpirun --oversubscribe -np "$NP" -x LP_NUM_THREADS=0 \
        ./build/bin/isowall wall --wall "$WALL" --out out/mosaic.png "$@"
fi
# ISOWALL_RECOVERY=1: a tile rank that dies does not end the wall (docs/wall.md, "When a tile rank
# dies"). mpirun then exits 0 whatever its ranks return, so the status comes from the master's
# lines: 1 after an error, 3 when the wall lost a rank.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
mpirun --enable-recovery --oversubscribe -np "$NP" -x LP_NUM_THREADS=0 \
    ./build/bin/isowall wall --wall "$WALL" --out out/mosaic.png "$@" 2>&1 | tee "$log"
if grep -q '^isowall: error:' "$log"; then exit 1; fi
if grep -q '^isowall: the wall lost' "$log"; then exit 3; fi
