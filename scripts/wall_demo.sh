#!/usr/bin/env bash
# Emulates a display wall on this machine: one master rank plus one rank per tile of the wall file,
# oversubscribed, writing the stitched mosaic. Usage: scripts/wall_demo.sh [WALL.toml] [isowall wall options]
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
mpirun --oversubscribe -np "$NP" -x LP_NUM_THREADS=0 \
    ./build/bin/isowall wall --wall "$WALL" --out out/mosaic.png "$@"
