#!/usr/bin/env bash
# The study runner's Slurm executor against a real, throwaway single-host
# Slurm cluster (Debian slurm-wlm: slurmctld and slurmd authenticating with
# munge, as a real cluster does; key, socket, config and state in a temporary
# directory, all started inside a private network
# namespace so it cannot meet any real Slurm): studies/tiny.toml submitted
# with --executor slurm must end with every run complete and equal, bit for
# bit, to the local executor's runs (same seeds). Bounded waits throughout.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
for b in munged munge slurmctld slurmd sbatch squeue scontrol; do
  command -v $b >/dev/null || { echo "FAIL $b not installed (launch_scripts/setup.sh installs slurm-wlm)"; exit 1; }
done
export BUILD_DIR=$build
tmp=$(mktemp -d)
d=$tmp/slurm
mkdir -p "$d/state" "$d/spool" "$d/munge"
chmod 700 "$d/munge"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  sleep 0.5
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"
}
trap cleanup EXIT
# glibc's AI_ADDRCONFIG ignores 127.0.0.1: without a second address on lo
# slurmctld cannot resolve itself in a namespace with nothing but loopback.
ip addr add 127.0.0.2/8 dev lo 2>/dev/null || true
host=$(hostname -s)
# munge: a fresh key of our own and a socket in the temporary directory, so
# the host's munged (if any) is never used or disturbed.
dd if=/dev/urandom of="$d/munge/key" bs=1024 count=1 status=none
chmod 600 "$d/munge/key"
msock=$d/munge/socket
munged -F --force --key-file="$d/munge/key" --socket="$msock" --pid-file="$d/munge/pid" \
  --log-file="$d/munge/log" --seed-file="$d/munge/seed" >"$d/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 100); do [[ -S $msock ]] && break; sleep 0.1; done
munge -S "$msock" -n | unmunge -S "$msock" >/dev/null ||
  { echo "FAIL munged did not start"; cat "$d/munged.out" "$d/munge/log" 2>/dev/null; exit 1; }
echo "ok   munged up, a credential round-trips"
: >"$d/plugstack.conf"
cat >"$d/slurm.conf" <<CONF
ClusterName=dynhettest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16917
SlurmdPort=16918
AuthType=auth/munge
AuthInfo=socket=$msock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
PlugStackConfig=$d/plugstack.conf
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
MinJobAge=600
DependencyParameters=kill_invalid_depend
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 RealMemory=4000 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$d/slurm.conf
slurmctld -D -i >"$d/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D >"$d/slurmd.out" 2>&1 &
pids+=($!)
ready=0
for _ in $(seq 300); do
  for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null || { echo "FAIL a Slurm daemon died at start:"; tail -20 "$d"/*.log "$d"/*.out; exit 1; }; done
  if sinfo -h -o %t 2>/dev/null | grep -q idle; then ready=1; break; fi
  sleep 0.1
done
((ready)) || { echo "FAIL the Slurm node did not come up in 30 s"; sinfo; tail -20 "$d"/*.log; exit 1; }
echo "ok   single-host Slurm cluster up ($(sinfo -h -o '%P %D %t'))"

fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --executor slurm --out "$tmp/s" \
  --time=10 >"$tmp/s.out" 2>&1 || { cat "$tmp/s.out"; tail -20 "$d"/*.log; exit 1; }
cat "$tmp/s.out"
check 'grep -q "4 runs submitted as Slurm job array" "$tmp/s.out"' "one job array of 4 tasks and an index job submitted"
# Meanwhile the same study on the local executor.
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --out "$tmp/l" --jobs 1 >"$tmp/l.out" 2>&1 ||
  { cat "$tmp/l.out"; exit 1; }
done_=0
for _ in $(seq 1800); do
  if [[ -z $(squeue -h -o %i 2>/dev/null) ]]; then done_=1; break; fi
  sleep 0.2
done
((done_)) || { echo "FAIL the Slurm jobs did not finish in 6 min"; squeue; exit 1; }
check '[[ $(grep -c "state = \"complete\"" "$tmp/s/index.toml") == 4 ]]' "the index job wrote an index with 4 complete runs"
check 'ls "$tmp"/s/slurm/task-*_0.out >/dev/null' "each task's log is in the study directory"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/l" "$tmp/s" || fail=1
# Again: nothing left to submit.
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --executor slurm --out "$tmp/s" >"$tmp/s2.out" 2>&1
check 'grep -q "nothing to submit" "$tmp/s2.out"' "submitted again: nothing to submit"
((fail == 0)) || { cat "$tmp"/*.out; tail -n 30 "$d"/*.log; for f in "$tmp"/s/slurm/*.out; do echo "== $f"; tail -n 5 "$f"; done; }
exit $fail
