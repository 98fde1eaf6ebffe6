#!/usr/bin/env bash
# The loopback gate decides on addresses, not on names: `isowall serve --listen NAME`, where NAME
# starts with "127." but the hosts file maps it to 0.0.0.0 (every interface), must be refused as
# `--listen 0.0.0.0` is (the same exit status, one line naming --listen), not serve the datasets
# in clear text without a token.
# A mount namespace gives the run a hosts file of its own. Exit 77 (skip) without root or unshare.
#   loopback_gate_test.sh /path/to/isowall
set -u
bin=$1
if [ "$(id -u)" != 0 ] || ! command -v unshare > /dev/null; then
    echo "loopback_gate_test: skip: needs root and unshare"
    exit 77
fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf '127.0.0.1 localhost\n0.0.0.0 127.attacker.test localhost.attacker.test\n' > "$dir/hosts"
if ! unshare --mount sh -c 'mount --bind "$1" /etc/hosts' sh "$dir/hosts" 2> /dev/null; then
    echo "loopback_gate_test: skip: no mount namespace here"
    exit 77
fi
"$bin" serve --listen 0.0.0.0:0 > "$dir/out" 2>&1
refused=$?
if [ "$refused" = 0 ] || ! grep -q "not loopback" "$dir/out"; then
    echo "loopback_gate_test: FAILED: --listen 0.0.0.0 was not refused (exit $refused)"
    exit 1
fi
status=0
for name in 127.attacker.test localhost.attacker.test; do
    unshare --mount sh -c 'mount --bind "$1" /etc/hosts && exec "$2" serve --listen "$3:0"' \
        sh "$dir/hosts" "$bin" "$name" > "$dir/out" 2>&1
    rc=$?
    lines=$(wc -l < "$dir/out")
    if [ "$rc" = "$refused" ] && [ "$lines" = 1 ] && grep -q -- "--listen" "$dir/out" &&
        grep -q "not loopback" "$dir/out"; then
        echo "loopback_gate_test: $name (0.0.0.0) refused: $(cat "$dir/out")"
    else
        echo "loopback_gate_test: FAILED: $name (0.0.0.0): exit $rc, $lines line(s):"
        cat "$dir/out"
        status=1
    fi
done
exit $status
