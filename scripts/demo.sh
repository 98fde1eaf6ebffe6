#!/usr/bin/env bash
# Quick start, first command: install, build, and render the built-in phantom to out/phantom.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out
./build/master/isowall render --out out/phantom.png "$@"
