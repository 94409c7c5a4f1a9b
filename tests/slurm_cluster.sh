# A throwaway single-host Slurm cluster for the tests (Debian slurm-wlm:
# slurmctld and slurmd authenticating with munge, as a real cluster does;
# key, socket, config and state in a temporary directory). Sourced by a
# test already inside a private network namespace, with $tmp set: it starts
# the daemons, exports SLURM_CONF, adds their pids to $pids and says "ok"
# once the node is idle; cleanup_slurm stops them. Bounded waits throughout.
pids=()
cleanup_slurm() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  sleep 0.5
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
}
for b in munged munge slurmctld slurmd sbatch squeue scontrol; do
  command -v $b >/dev/null || { echo "FAIL $b not installed (launch_scripts/setup.sh installs slurm-wlm)"; exit 1; }
done
d=$tmp/slurm
mkdir -p "$d/state" "$d/spool" "$d/munge"
chmod 700 "$d/munge"
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

