#!/bin/sh
# Runs the page end to end through the bridge and compares its images with `isowall render`'s:
#   web/tools/run_e2e.sh /work/build-h13p/master/isowall OUT_DIR
# Starts tools/bridge.mjs (which starts `isowall serve --port 0`), runs test/e2e_page.mjs and
# test/e2e_errors.mjs, renders the views the page drew (views.json) with `isowall render`, and
# prints compare_images.py's figures (IoU >= 0.99 and 99% of covered pixels within 2/255 required).
set -eu
ISOWALL=${1:?usage: run_e2e.sh ISOWALL OUT_DIR}
OUT=${2:?usage: run_e2e.sh ISOWALL OUT_DIR}
WEB=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$OUT"
node "$WEB/tools/bridge.mjs" --spawn "$ISOWALL" > "$OUT/bridge.log" 2>&1 &
BRIDGE=$!
trap 'kill $BRIDGE 2>/dev/null || true' EXIT
for i in $(seq 1 100); do
  URL=$(sed -n 's/^bridge: page at \(http:[^ ]*\).*/\1/p' "$OUT/bridge.log")
  [ -n "$URL" ] && break
  sleep 0.2
done
[ -n "$URL" ] || { cat "$OUT/bridge.log"; exit 1; }
ISOWALL_PAGE_URL=$URL ISOWALL_OUT=$OUT node "$WEB/test/e2e_page.mjs"
ISOWALL_BIN=$ISOWALL node "$WEB/test/e2e_errors.mjs"
status=0
for view in front iso2 dragged zoomed; do
  set -- $(/usr/bin/python3 -c "import json,sys; v=json.load(open(sys.argv[1]))[sys.argv[2]]; print(repr(v['yaw']), repr(v['pitch']), repr(v['zoom']), repr(v['iso']), '%dx%d' % (v['width'], v['height']))" "$OUT/views.json" $view)
  "$ISOWALL" render --size "$5" --orbit "$1" "$2" --zoom "$3" --iso "$4" --out "$OUT/ref_$view.png" > "$OUT/render_$view.log"
  echo "== $view: yaw $1 pitch $2 zoom $3 iso $4 ($5)"
  /usr/bin/python3 "$WEB/test/compare_images.py" "$OUT/$view.png" "$OUT/ref_$view.png" \
    --min-iou 0.99 --min-within2 0.99 --diff "$OUT/diff_$view.png" || status=1
done
exit $status
