#!/usr/bin/env bash
# After a change to the cells codec (remote/cell_codec.cpp, cell_units.cpp, cell_voxels.h,
# cell_values.h, cell_predict.h, range_coder.h) and the fuzz seeds made again from it
# (web/README.md): makes everything of the page's that follows from it again, from the sources of one build folder:
#   1. test/data/cells_groups.bin: the test groups and the meshes the C++ decodes them to
#      (test/data/cells_probe.cpp, linked against that build's libraries, which it brings up to
#      date; the seed corpus's cells groups are read from fuzz/corpus/group_codec there);
#   2. src/cells_wasm.js (build.sh, from the same sources);
#   3. src/cells_warm.js: two of the seed corpus's cells groups, which the page decodes once as
#      it starts (group_codec.js) so the browser compiles the decoder before the first group;
#   4. dist/ (npm run build).
# Then run `npm test` in web/ and commit the three.
#   web/wasm/refresh.sh [BUILD_DIR]      (default: build/ of this checkout)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
web=$(cd "$here/.." && pwd)
build=$(cd "${1:-$web/../build}" && pwd)
root=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt")
[ -n "$root" ] || { echo "wasm/refresh.sh: $build is not a CMake build folder" >&2; exit 1; }

cmake --build "$build" -j "$(nproc)" --target isowall_remote_codec > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
g++ -std=c++20 -O2 -DGLM_FORCE_XYZW_ONLY -DGLM_ENABLE_EXPERIMENTAL -I"$root" \
    "$web/test/data/cells_probe.cpp" "$build/remote/libisowall_remote_codec.a" \
    "$build/extract/libisowall_extract.a" "$build/volume/libisowall_volume.a" \
    "$build/core/libisowall_core.a" "$build/files/libisowall_files.a" -lteem -lz -lbz2 -lmeshoptimizer -lzstd -o "$tmp/cells_probe"
# The CT head adds a real 16-bit volume's groups when the shared data is there.
cthead=$root/../shared/data/cthead.nhdr
[ -f "$cthead" ] || cthead=
"$tmp/cells_probe" reference "$web/test/data/cells_groups.bin" "$root/fuzz/corpus/group_codec" \
    ${cthead:+"$cthead"} | tail -1
"$here/build.sh" "$web/src/cells_wasm.js" "$root"
node - "$root/fuzz/corpus/group_codec" "$web/src/cells_warm.js" <<'JS'
const { readFileSync, writeFileSync } = require('node:fs');
const [corpus, out] = process.argv.slice(2);
const bytes = (n) => `  new Uint8Array([${[...readFileSync(`${corpus}/${n}`)].join(', ')}]),`;
writeFileSync(out, [
  '// Made by web/wasm/refresh.sh from fuzz/corpus/group_codec (cells-phantom-cells and',
  '// cells-phantom-level2); do not edit. Two small groups in the cells encoding, a full-resolution',
  '// pass and a coarse one, that the page decodes once as it starts (group_codec.js: ready), so the',
  '// browser compiles the decoder before the first group arrives rather than while it waits.',
  '/* eslint-disable */',
  'export const warmGroups = [',
  bytes('cells-phantom-cells'),
  bytes('cells-phantom-level2'),
  '];',
  ''].join('\n'));
JS
(cd "$web" && node tools/build.mjs)
