#!/usr/bin/env bash
# Quick start, first command: install, build, and run the main job, the display wall emulated on
# this machine (walls/2x2.toml: a master and four tile ranks under mpirun) on the built-in phantom,
# writing the mosaic to out/mosaic.png. Extra arguments go to `isowall wall`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Balancing is on by default; --measure adds the emulated time to wall-wide C = 90/99/100%.
bash scripts/wall_demo.sh walls/2x2.toml --measure "$@"
