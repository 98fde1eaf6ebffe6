#!/bin/sh
# The page end to end in headless Chromium, against the real server (CTest: web_page_e2e):
#   web/tools/run_e2e.sh ISOWALL OUT_DIR
# Starts `isowall serve --port 0 --http 0`, runs test/e2e_page.mjs (front view, slider, drag,
# wheel, bad isovalue, picker), test/e2e_errors.mjs (which starts its own server with a token) and
# test/e2e_tls.mjs (its own server over TLS: https, wss, the front view),
# draws each view the page drew (views.json) with `isowall render`, and compares the images with
# compare_images.py: mask IoU >= 0.99 and 99% of the pixels both cover within 2/255.
set -eu
ISOWALL=${1:?usage: run_e2e.sh ISOWALL OUT_DIR}
OUT=${2:?usage: run_e2e.sh ISOWALL OUT_DIR}
WEB=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$OUT"
# A 20 Mbit/s link (the server's own pacing): there cells pay, so the page decodes and draws
# them; to a page on loopback unpaced the server sends compact+zstd alone (encoding_choice.h).
"$ISOWALL" serve --port 0 --http 0 --rate-mbps 20 > "$OUT/serve.log" 2>&1 &
SERVE=$!
trap 'kill -INT $SERVE 2>/dev/null || true' EXIT
URL=
for _ in $(seq 1 300); do
    URL=$(sed -n 's/^serve: page at \(http:[^ ]*\).*/\1/p' "$OUT/serve.log")
    [ -n "$URL" ] && break
    kill -0 $SERVE 2>/dev/null || break
    sleep 0.2
done
[ -n "$URL" ] || { echo "run_e2e: isowall serve printed no page line:"; cat "$OUT/serve.log"; exit 1; }
ISOWALL_PAGE_URL=$URL ISOWALL_OUT=$OUT node "$WEB/test/e2e_page.mjs"
ISOWALL_BIN=$ISOWALL node "$WEB/test/e2e_errors.mjs"
ISOWALL_BIN=$ISOWALL ISOWALL_OUT=$OUT node "$WEB/test/e2e_tls.mjs"
status=0
for view in front iso2 dragged zoomed; do
    set -- $(/usr/bin/python3 -c "import json,sys; v=json.load(open(sys.argv[1]))[sys.argv[2]]; print(repr(v['yaw']), repr(v['pitch']), repr(v['zoom']), repr(v['iso']), '%dx%d' % (v['width'], v['height']))" "$OUT/views.json" $view)
    "$ISOWALL" render --size "$5" --orbit "$1" "$2" --zoom "$3" --iso "$4" --out "$OUT/ref_$view.png" > "$OUT/render_$view.log"
    echo "== $view: yaw $1 pitch $2 zoom $3 iso $4 ($5)"
    /usr/bin/python3 "$WEB/test/compare_images.py" "$OUT/$view.png" "$OUT/ref_$view.png" \
        --min-iou 0.99 --min-within2 0.99 --diff "$OUT/diff_$view.png" || status=1
done
echo "== the front view over TLS (e2e_tls.mjs), against the same reference"
/usr/bin/python3 "$WEB/test/compare_images.py" "$OUT/tls_front.png" "$OUT/ref_front.png" \
    --min-iou 0.99 --min-within2 0.99 --diff "$OUT/diff_tls_front.png" || status=1
exit $status
