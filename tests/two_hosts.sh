#!/usr/bin/env bash
# Several hosts, as two network namespaces joined by a veth pair (the only
# interface of each besides loopback, addresses only on the veth): the sim
# runs in one (run_scene.sh --bus lan --role sim), the nodes and the
# recorder in the other (--role analysis), ttl=1 across the link. The run
# must lose no frame, end complete, and its results must equal those of the
# same scene and run id on one host, bit for bit. Also: --role without
# --run-id, and --role on a private bus, are refused.
set -euo pipefail
root=$1 build=$2
export BUILD_DIR=$build
tmp=$(mktemp -d)
na=dynhetA$$ nb=dynhetB$$ va=dva$$ vb=dvb$$
cleanup() {
  ip netns pids "$na" 2>/dev/null | xargs -r kill 2>/dev/null || true
  ip netns pids "$nb" 2>/dev/null | xargs -r kill 2>/dev/null || true
  ip netns del "$na" 2>/dev/null || true
  ip netns del "$nb" 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
scene=(bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --no-build)

"${scene[@]}" --bus lan --role sim >"$tmp/r1.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "needs --run-id" "$tmp/r1.out"' "--role without --run-id is refused"
"${scene[@]}" --role analysis --run-id 5 >"$tmp/r2.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "use --bus lan" "$tmp/r2.out"' "--role on the private bus is refused"

# The reference: one host (a private namespace).
"${scene[@]}" --run-id 777 --out "$tmp/one" >"$tmp/one.log" 2>&1 || { tail -5 "$tmp/one.log"; exit 1; }

ip netns add "$na"
ip netns add "$nb"
ip link add "$va" type veth peer name "$vb"
ip link set "$va" netns "$na"
ip link set "$vb" netns "$nb"
for x in "$na:$va:10.213.7.1" "$nb:$vb:10.213.7.2"; do
  IFS=: read -r ns dev addr <<<"$x"
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "$addr/24" dev "$dev"
  ip -n "$ns" link set "$dev" up
  ip -n "$ns" link set "$dev" multicast on
  ip -n "$ns" route add 224.0.0.0/4 dev "$dev"
done
url='udpm://239.255.76.67:7715?ttl=1'
ip netns exec "$nb" "${scene[@]}" --bus lan --url "$url" --role analysis --run-id 777 --out "$tmp/b" >"$tmp/b.log" 2>&1 &
analysis=$!
for _ in $(seq 100); do grep -q "waiting for run 777" "$tmp/b.log" 2>/dev/null && break; sleep 0.1; done
# The run's key, made by the analysis host, copied to the sim's (docs/bus.md).
check '[[ -f $tmp/b/bus.key && $(stat -c %a "$tmp/b/bus.key") == 600 ]]' "the analysis host wrote the run's key (mode 600)"
ip netns exec "$na" "${scene[@]}" --bus lan --url "$url" --role sim --run-id 777 --out "$tmp/a" >"$tmp/a0.log" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "role sim needs --key-file" "$tmp/a0.log"' "--role sim without the run's key is refused"
mkdir -p "$tmp/a" && cp -p "$tmp/b/bus.key" "$tmp/a/copied.key"
ip netns exec "$na" "${scene[@]}" --bus lan --url "$url" --role sim --run-id 777 --out "$tmp/a" --key-file "$tmp/a/copied.key" \
  >"$tmp/a.log" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "the sim on host A ran (exit $rc)"
wait "$analysis" && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "the analysis on host B ended well (exit $rc)"
check '[[ ! -e $tmp/a/run.h5 && -e $tmp/b/run.h5 ]]' "the results are on host B only"
check '/usr/bin/python3 -c "
import h5py, sys
f = h5py.File(sys.argv[1], \"r\")
lost = {k: int(v) for k, v in f.attrs.items() if k.startswith(\"frames_lost\")}
print(\"   \", lost, \"complete\", int(f.attrs[\"complete\"]))
sys.exit(0 if int(f.attrs[\"complete\"]) == 1 and lost and not any(lost.values()) else 1)" "$tmp/b/run.h5"' "across the veth: complete, 0 frames lost by any node"
check 'PYTHONPATH="$root/tests" /usr/bin/python3 -c "
import sys
from compare_runs import final_results, same
(a, _), (b, _) = final_results(sys.argv[1]), final_results(sys.argv[2])
sys.exit(0 if same(a, b) else 1)" "$tmp/one/run.h5" "$tmp/b/run.h5"' "the two-host results equal the one-host run's bit for bit"
check '[[ $(ip -n "$nb" -4 -o addr show | grep -v " lo " | wc -l) == 1 ]]' "host B's only address is on the veth"
((fail == 0)) || { tail -20 "$tmp/a.log" "$tmp/b.log"; }
exit $fail
