#!/usr/bin/env bash
# Runs a command in a private network namespace whose only interface is
# loopback with multicast routed to it, so no LCM packet leaves the machine.
# Usage: launch_scripts/netns.sh COMMAND [ARGS...]   (needs root or user namespaces)
set -euo pipefail
case ${1:-} in
-h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
"") awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0" >&2; exit 2 ;;
esac
if [[ "${DYNHET_IN_NETNS:-}" == 1 ]]; then exec "$@"; fi
if [[ $EUID -eq 0 ]]; then flag=-n; else flag=-rn; fi
exec unshare $flag env DYNHET_IN_NETNS=1 bash -c '
  ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo || {
    echo "netns.sh: cannot set up loopback multicast in the namespace" >&2; exit 97; }
  exec "$@"' netns "$@"
