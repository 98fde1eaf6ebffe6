#!/usr/bin/env bash
# Emulates a small cluster on this machine and runs a command on its first host (the console).
#
#   netns_hosts.sh [--slots 2,2,1] [--dir DIR] -- COMMAND [ARG...]
#   netns_hosts.sh clean      # removes what runs killed with SIGKILL left behind
#
# Every host is a network namespace of its own (iw-RUN-h1, iw-RUN-h2...: RUN is this script's
# pid, so runs side by side never meet) with one veth link, eth0, to a bridge in a fourth
# namespace (iw-RUN-sw), and the address 10.77.0.N/24. Nothing is added to this machine's own
# network namespace, so the fixed subnet cannot clash with its networks or with another run.
# The host's name is hN (a UTS namespace of its own, set by scripts/netns_agent.sh).
#
# DIR (default: a temporary folder) receives a plain hostfile, one line per host in --slots
# order ("10.77.0.1 slots=2"), and the map the launch agent reads (hosts.netns: ADDRESS NAMESPACE
# HOSTNAME). COMMAND runs on h1 with these set:
#   ISOWALL_NETNS_HOSTFILE  DIR/hostfile         (mpirun --hostfile)
#   ISOWALL_NETNS_AGENT     scripts/netns_agent.sh (mpirun --mca plm_rsh_agent)
#   ISOWALL_NETNS_MAP       DIR/hosts.netns       (read by the agent)
#   ISOWALL_NETNS_SUBNET    10.77.0.0/24          (--mca oob_tcp_if_include, btl_tcp_if_include)
# The exit status is COMMAND's. On exit, INT or TERM every process left in the namespaces is
# ended and the namespaces are deleted. Exit 77 (and one line) when this machine cannot do it:
# not root, no `ip netns`, no veth or bridge links.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
readonly kSubnet=10.77.0
readonly kSkip=77

skip() {
    echo "netns_hosts: skip: $*" >&2
    exit "$kSkip"
}

fail() {
    echo "netns_hosts: error: $*" >&2
    exit 2
}

# Namespaces whose name starts with PREFIX, one a line.
namespaces_of() {
    ip netns list 2>/dev/null | awk -v p="$1" 'index($1, p) == 1 { print $1 }'
}

# Ends every process inside the namespaces (TERM, then KILL after 2 s), then deletes them.
remove_namespaces() {
    local list pids
    mapfile -t list < <(namespaces_of "$1")
    [ ${#list[@]} -gt 0 ] || return 0
    for i in $(seq 30); do
        mapfile -t pids < <(for ns in "${list[@]}"; do ip netns pids "$ns" 2>/dev/null || true; done)
        [ ${#pids[@]} -gt 0 ] || break
        if [ "$i" -eq 1 ]; then kill -TERM "${pids[@]}" 2>/dev/null || true; fi
        if [ "$i" -eq 20 ]; then kill -KILL "${pids[@]}" 2>/dev/null || true; fi
        sleep 0.1
    done
    for ns in "${list[@]}"; do ip netns del "$ns" 2>/dev/null || true; done
}

# Namespaces of runs whose script is gone (killed with SIGKILL, so its trap never ran).
clean_stale() {
    local pid
    for pid in $(ip netns list 2>/dev/null | sed -n 's/^iw-\([0-9][0-9]*\)-.*/\1/p' | sort -u); do
        kill -0 "$pid" 2>/dev/null || remove_namespaces "iw-$pid-"
    done
}

if [ "${1:-}" = clean ]; then
    clean_stale
    exit 0
fi

slots=2,2,1
dir=
while [ $# -gt 0 ]; do
    case $1 in
        --slots) slots=${2:?--slots needs a value}; shift 2 ;;
        --dir) dir=${2:?--dir needs a value}; shift 2 ;;
        --) shift; break ;;
        *) fail "unknown argument '$1' (usage: netns_hosts.sh [--slots 2,2,1] [--dir DIR] -- COMMAND...)" ;;
    esac
done
[ $# -gt 0 ] || fail "no COMMAND after -- (usage: netns_hosts.sh [--slots 2,2,1] [--dir DIR] -- COMMAND...)"
IFS=, read -r -a slot_list <<<"$slots"
for s in "${slot_list[@]}"; do
    [[ $s =~ ^[1-9][0-9]?$ ]] || fail "--slots: expected positive counts like 2,2,1, got '$slots'"
done
[ ${#slot_list[@]} -le 200 ] || fail "--slots: expected at most 200 hosts, got ${#slot_list[@]}"

[ "$(id -u)" -eq 0 ] || skip "network namespaces need root (running as uid $(id -u))"
command -v ip >/dev/null || skip "no 'ip' command (Debian: apt-get install iproute2)"
command -v unshare >/dev/null || skip "no 'unshare' command (Debian: util-linux)"

readonly run="iw-$$-"
child=
tmp_dir=
# shellcheck disable=SC2317  # teardown and on_signal run from the traps below
teardown() {
    remove_namespaces "$run"
    if [ -n "$tmp_dir" ]; then rm -rf "$tmp_dir"; fi
}
# shellcheck disable=SC2317
on_signal() {
    # Ignored from now on, not reset: `timeout` sends TERM to this script and then to its whole
    # process group, and a second TERM must not end the teardown half way.
    trap '' INT TERM
    if [ -n "$child" ]; then kill -TERM "$child" 2>/dev/null || true; fi
    exit $((128 + $1))
}
trap teardown EXIT
trap 'on_signal 2' INT
trap 'on_signal 15' TERM

clean_stale
if [ -z "$dir" ]; then
    tmp_dir=$(mktemp -d)
    dir=$tmp_dir
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

# The switch: a bridge alone in its namespace. A failure here is this machine's, not the
# caller's: no netns support (a container without CAP_SYS_ADMIN), or no bridge module.
sw="${run}sw"
err=$(ip netns add "$sw" 2>&1) || skip "'ip netns add' failed: $err"
err=$(ip -n "$sw" link add br0 type bridge 2>&1) || skip "no bridge links: $err"
ip -n "$sw" link set br0 up
: >"$dir/hostfile"
echo "# ADDRESS NAMESPACE HOSTNAME (scripts/netns_agent.sh)" >"$dir/hosts.netns"
for i in $(seq ${#slot_list[@]}); do
    ns="${run}h$i"
    ip netns add "$ns"
    err=$(ip -n "$sw" link add "p$i" type veth peer name eth0 netns "$ns" 2>&1) ||
        skip "no veth links: $err"
    ip -n "$sw" link set "p$i" master br0 up
    ip -n "$ns" addr add "$kSubnet.$i/24" dev eth0
    ip -n "$ns" link set eth0 up
    ip -n "$ns" link set lo up
    echo "$kSubnet.$i slots=${slot_list[$((i - 1))]}" >>"$dir/hostfile"
    echo "$kSubnet.$i $ns h$i" >>"$dir/hosts.netns"
done

export ISOWALL_NETNS_HOSTFILE="$dir/hostfile" ISOWALL_NETNS_MAP="$dir/hosts.netns"
export ISOWALL_NETNS_AGENT="$here/netns_agent.sh" ISOWALL_NETNS_SUBNET="$kSubnet.0/24"
# In the background, so that INT and TERM reach the trap at once (bash runs a trap only after the
# foreground command ends). The agent enters h1 the way it enters every host.
"$here/netns_agent.sh" "$kSubnet.1" "$(printf '%q ' "$@")" &
child=$!
rc=0
wait "$child" || rc=$?
exit "$rc"
