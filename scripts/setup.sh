#!/usr/bin/env bash
# Installs what isowall needs on Debian 12 (as root, with apt-get) and builds it in build/.
# Safe to run again: packages already present are not reinstalled, the build is incremental.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
    build-essential cmake pkg-config clang-format clang
    libglm-dev libteem-dev zlib1g-dev libbz2-dev libtomlplusplus-dev libcli11-dev
    libopenimageio-dev openimageio-tools
    libosmesa6-dev libegl-dev libegl-mesa0 libgl-dev libgl1-mesa-dri libgles-dev
    libopenmpi-dev openmpi-bin
    libgtest-dev libgmock-dev libbenchmark-dev
    libmeshoptimizer-dev libzstd-dev libblosc-dev liblz4-dev libcurl4-openssl-dev
    nlohmann-json3-dev libwebsocketpp-dev
    libasio-dev
    libssl-dev openssl
    libembree-dev python3-vtk9
    libgdcm-dev libnifti2-dev libhdf5-dev
    python3 python3-numpy python3-matplotlib python3-zarr
    libx11-dev libxext-dev xvfb xdotool x11-apps x11-utils iproute2
    nodejs chromium emscripten
)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=()
for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${missing[*]}"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# npm: part of some nodejs packages (NodeSource's), a package of its own in Debian's.
if ! command -v npm > /dev/null; then
    echo "setup: installing npm"
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends npm
fi
# The page's packages (web/package-lock.json): the bundler, and playwright-core for the browser
# tests. Installed again only when the lock file changed since the last install.
if [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then
    echo "setup: npm ci in web/"
    npm ci --prefix web --no-audit --no-fund --loglevel=error
fi

BUILD_DIR=${ISOWALL_BUILD_DIR:-build}
# A unity build (CMake compiles each folder's sources in batches of 16 as one file, so the common
# headers are parsed once per batch): a fresh build on 2 cores took 6 min against 15 file by
# file. ISOWALL_UNITY=OFF builds file by file, which rebuilds less after a one-file change.
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DISOWALL_WERROR=ON \
    -DCMAKE_UNITY_BUILD="${ISOWALL_UNITY:-ON}" -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 > /dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)"
