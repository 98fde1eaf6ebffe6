#!/usr/bin/env bash
# Open MPI's launch agent for emulated hosts (scripts/netns_hosts.sh): used in place of ssh with
# `mpirun --mca plm_rsh_agent scripts/netns_agent.sh`. Usage: netns_agent.sh HOST COMMAND...
#
# HOST is a host's address or name as the hostfile gives it. The map file named by
# $ISOWALL_NETNS_MAP says where it lives, one host a line: ADDRESS NAMESPACE HOSTNAME. Like ssh,
# the agent joins COMMAND into one line and hands it to the host's shell, because Open MPI quotes
# the daemon's arguments for a remote shell. The shell runs in the host's network namespace and in
# a UTS namespace of its own named HOSTNAME, so every rank there reports that host.
#
# With ISOWALL_NETNS_HIDE=DIR (a folder), every host but h1 also gets a mount namespace of its own
# with an empty tmpfs over DIR: what lies there is seen only on h1, as data on a console node's
# disk that the display nodes cannot reach.
set -euo pipefail

fail() {
    echo "netns_agent: error: $*" >&2
    exit 255 # what ssh returns when it cannot reach the host
}

map=${ISOWALL_NETNS_MAP:-}
[ -n "$map" ] || fail "ISOWALL_NETNS_MAP: expected the map file of scripts/netns_hosts.sh, got nothing"
[ -r "$map" ] || fail "ISOWALL_NETNS_MAP: expected a readable file, got '$map'"
[ $# -ge 2 ] || fail "expected HOST COMMAND..., got $# arguments"
host=$1
shift

entry=$(awk -v h="$host" '!/^#/ && ($1 == h || $3 == h) { print $2, $3; exit }' "$map")
[ -n "$entry" ] || fail "$map: host '$host' is not in the map"
read -r ns name <<<"$entry"

hide=${ISOWALL_NETNS_HIDE:-}
if [ -n "$hide" ] && [ "$name" != h1 ]; then
    [ -d "$hide" ] || fail "ISOWALL_NETNS_HIDE: expected a folder, got '$hide'"
    # shellcheck disable=SC2016  # $1..$3 are the inner shell's, not ours
    exec ip netns exec "$ns" unshare --uts --mount bash -c \
        'hostname "$1" && mount -t tmpfs hidden "$3" && exec bash -c "$2"' \
        netns_agent "$name" "$*" "$hide"
fi
# shellcheck disable=SC2016  # $1 and $2 are the inner shell's, not ours
exec ip netns exec "$ns" unshare --uts bash -c 'hostname "$1" && exec bash -c "$2"' \
    netns_agent "$name" "$*"
