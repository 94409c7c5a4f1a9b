#!/usr/bin/env bash
# A run longer than its Slurm time limit completes through requeues. On a
# throwaway single-host Slurm cluster (tests/slurm_cluster.sh) in a private
# network namespace: a one-run study whose production needs about three
# times the task's --time (1 minute; the sim sleeps 1.5 s before each of its
# 56 frames, a stand-in for a large N), on the Slurm executor with
# --signal-lead 45: before each time limit Slurm sends SIGTERM, the run
# takes a last checkpoint cut and stops (exit 75), the task requeues itself
# and resumes from the cut. Slurm holds a requeued job for two minutes
# (BeginTime); the test releases each hold as an administrator may
# (scontrol update StartTime=now) so that it lasts minutes, not ten.
# Meanwhile the same study on the local executor,
# straight through. The Slurm run must complete after at least two
# requeues (counted in the index) and equal the local run bit for bit
# (tests/compare_h5.py: every dataset and attribute but the wall-clock ones).
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'cleanup_slurm; [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
source "$root/tests/slurm_cluster.sh"

fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
sed 's/^equilibration_time = 5.0/equilibration_time = 5.0\ncheckpoint_interval = 0.5/' "$root/scenes/tiny.toml" >"$tmp/scene.toml"
cat >"$tmp/requeue.toml" <<'TOML'
[study]
name = "requeue"
description = "one run longer than its Slurm time limit"
scene = "scene.toml"

[axes]
seed = [7]

[run_length]
tau_alpha = "scene"
TOML
export DYNHET_TEST_SIM_DELAY=1.5
bash "$root/launch_scripts/run_study.sh" "$tmp/requeue.toml" --no-build --no-figures --executor slurm --out "$tmp/s" --time=1 \
  --signal-lead 45 >"$tmp/s.out" 2>&1 || { cat "$tmp/s.out"; tail -20 "$d"/*.log; exit 1; }
( # the administrator: a requeued task waiting out its hold may start now,
  # once the node has let go of its previous allocation. A task that
  # requeues itself shows as PENDING while its script still ends, and a
  # start within the second its credential was revoked is killed ("Job
  # credential revoked", seen in CI 0.2 s after the requeue): release a job
  # only after it and an idle node have been seen for 4 s on end.
  declare -A since
  while sleep 1; do
    now=$(date +%s)
    declare -A seen=()
    if sinfo -h -o %T 2>/dev/null | grep -qx idle; then
      for j in $(squeue -h -t PENDING -o "%i %r" 2>/dev/null | awk '$2 == "BeginTime" { print $1 }'); do
        scontrol show job -o "$j" 2>/dev/null | grep -q "JobState=PENDING " || continue
        seen[$j]=1
        since[$j]=${since[$j]:-$now}
        if ((now - since[$j] >= 4)); then
          scontrol update JobId="$j" StartTime=now 2>/dev/null && echo "$(date '+%T') released $j" >>"$tmp/released.out"
          unset "seen[$j]"
        fi
      done
    fi
    for j in "${!since[@]}"; do [[ -n ${seen[$j]:-} ]] || unset "since[$j]"; done
    unset seen
  done
) &
pids+=($!)
check 'grep -q "1 runs submitted as Slurm job array" "$tmp/s.out"' "one task submitted, with a time limit of 1 minute"
# Meanwhile the same study on the local executor (it sleeps, as the task does).
bash "$root/launch_scripts/run_study.sh" "$tmp/requeue.toml" --no-build --no-figures --out "$tmp/l" --jobs 1 >"$tmp/l.out" 2>&1 ||
  { cat "$tmp/l.out"; exit 1; }
done_=0
for _ in $(seq 2400); do # 8 minutes at most
  if [[ -z $(squeue -h -o %i 2>/dev/null) ]]; then done_=1; break; fi
  sleep 0.2
done
((done_)) || { echo "FAIL the Slurm jobs did not finish in 8 min"; squeue; }
task_out=$(ls "$tmp"/s/slurm/task-*_0.out 2>/dev/null | head -1)
[[ -n $task_out ]] && grep -E "task |requeued|interrupted|died|failed" "$task_out" | tail -40
run=$(ls -d "$tmp"/s/runs/*/ 2>/dev/null | head -1)
check '[[ $(grep -c "state = \"complete\"" "$tmp/s/index.toml") == 1 ]]' "the run completes through requeues"
requeues=$(sed -n 's/^requeues = \([0-9]*\)/\1/p' "$tmp/s/index.toml")
check '[[ ${requeues:-0} -ge 2 ]]' "the index counts its requeues (${requeues:-none}; the run needs about three time limits)"
check '[[ $(grep -c "requeued$" "$task_out") -ge 2 ]]' "the task says each time it was interrupted and requeued"
check '[[ $(grep -c "requeued .* times)" "$task_out") -ge 3 ]]' "the task started three times or more"
check 'grep -q "resuming run .* from checkpoint cut" "$run/run_scene.log"' "each segment resumes from a checkpoint cut"
lrun=$(ls -d "$tmp"/l/runs/*/ | head -1)
# The two study directories each name their own prepared state in the
# scene, and each run draws its own run id.
check '/usr/bin/python3 "$root/tests/compare_h5.py" "$lrun/run.h5" "$run/run.h5" --ignore parameters/scene_toml \
  --ignore parameters/system@initial_state --ignore parameters/run_info@run_id' \
  "the requeued run's run.h5 equals the local executor's, bit for bit but the wall clock (the state's path, the run id)"
((fail == 0)) || { cat "$tmp"/*.out; tail -n 30 "$d"/slurmctld.log; [[ -z $task_out ]] || cat "$task_out"; }
exit $fail
