#!/usr/bin/env bash
# The study runner's Slurm executor against a real, throwaway single-host
# Slurm cluster (Debian slurm-wlm: slurmctld and slurmd authenticating with
# munge, as a real cluster does; key, socket, config and state in a temporary
# directory, all started inside a private network
# namespace so it cannot meet any real Slurm): studies/tiny.toml submitted
# with --executor slurm must end with every run complete and equal, bit for
# bit, to the local executor's runs (same seeds); a run marked failed and
# submitted again must start over, not resume its failed attempt, and come
# out equal again; a submission that fails halfway leaves no held array
# behind. Bounded waits throughout.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'cleanup_slurm; [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
source "$root/tests/slurm_cluster.sh"

fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
wait_queue() { # until the queue is empty, at most 6 minutes
  for _ in $(seq 1800); do
    [[ -n $(squeue -h -o %i 2>/dev/null) ]] || return 0
    sleep 0.2
  done
  echo "FAIL $1 did not finish in 6 min"; squeue; exit 1
}
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --executor slurm --out "$tmp/s" \
  --time=10 >"$tmp/s.out" 2>&1 || { cat "$tmp/s.out"; tail -20 "$d"/*.log; exit 1; }
cat "$tmp/s.out"
check 'grep -q "4 runs submitted as Slurm job array" "$tmp/s.out"' "one job array of 4 tasks and an index job submitted"
# Meanwhile the same study on the local executor.
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --out "$tmp/l" --jobs 1 >"$tmp/l.out" 2>&1 ||
  { cat "$tmp/l.out"; exit 1; }
wait_queue "the Slurm jobs"
check '[[ $(grep -c "state = \"complete\"" "$tmp/s/index.toml") == 4 ]]' "the index job wrote an index with 4 complete runs"
check 'ls "$tmp"/s/slurm/task-*_0.out >/dev/null' "each task's log is in the study directory"
check 'grep -q -- "--analyse --no-figures" "$tmp"/s/slurm/index-*.sbatch && [[ -f $tmp/s/study.h5 ]] && ! ls "$tmp"/s/figures/*.png >/dev/null 2>&1' \
  "run_study.sh --no-figures reaches the index job: its analysis wrote study.h5, no figure"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/l" "$tmp/s" || fail=1
# Again: nothing left to submit.
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --executor slurm --out "$tmp/s" >"$tmp/s2.out" 2>&1
check 'grep -q "nothing to submit" "$tmp/s2.out"' "submitted again: nothing to submit"
# A new machine: a study directory gone, its runs all in the archive. Nothing
# is run; the index job alone is submitted, and analyses the study.
/usr/bin/python3 "$root/launch_scripts/study.py" archive "$tmp/l" --to "$tmp/arch" >"$tmp/ar.out" 2>&1 || { cat "$tmp/ar.out"; exit 1; }
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --executor slurm --out "$tmp/s4" \
  --archive "$tmp/arch" --time=10 >"$tmp/s4.out" 2>&1 || { cat "$tmp/s4.out"; exit 1; }
wait_queue "the index job alone"
check 'grep -q "4 runs complete in the archive" "$tmp/s4.out" && grep -q "every run complete in the archive; index job" "$tmp/s4.out" &&
  ! ls "$tmp"/s4/slurm/array-*.sbatch >/dev/null 2>&1 && [[ -f $tmp/s4/study.h5 ]]' \
  "every run in the archive: no array, the index job alone analysed the study"
# A run that failed, submitted again, starts over: the queue keeps what it was
# (previous_state), it is not resumed from its failed attempt's checkpoints.
run=$(ls "$tmp/s/runs" | head -1)
sed -i 's/^state = "complete"/state = "failed"/' "$tmp/s/runs/$run/status.toml"
bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --executor slurm --out "$tmp/s" \
  --time=10 >"$tmp/s3.out" 2>&1 || { cat "$tmp/s3.out"; exit 1; }
check 'grep -q "1 runs submitted as Slurm job array" "$tmp/s3.out"' "the failed run submitted again, alone"
wait_queue "the resubmitted job"
check 'grep -q "$run: failed before" "$tmp"/s/slurm/task-*.out' "its task ran it again from the start"
check '! grep -q "$run: was interrupted" "$tmp"/s/slurm/task-*.out' "its task did not resume its failed attempt"
check '[[ $(grep -c "state = \"complete\"" "$tmp/s/index.toml") == 4 ]]' "the index: 4 complete runs again"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/l" "$tmp/s" || fail=1
# A submission that fails after sbatch (here a run directory that cannot be
# made: a file in its place) leaves no held array behind and puts back what
# the runs were.
runs=($(ls "$tmp/s/runs"))
sed -i 's/^state = "complete"/state = "failed"/' "$tmp/s/runs/${runs[0]}/status.toml"
rm -rf "$tmp/s/runs/${runs[1]}" && touch "$tmp/s/runs/${runs[1]}"
rc=0; bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --no-build --no-figures --executor slurm --out "$tmp/s" \
  --time=10 >"$tmp/s4.out" 2>&1 || rc=$?
check '[[ $rc != 0 ]]' "a submission that cannot write its runs' statuses fails (exit $rc)"
check '[[ -z $(squeue -h -o %i 2>/dev/null) ]]' "and leaves no job in the queue (its held array cancelled)"
check 'grep -q "^state = \"failed\"" "$tmp/s/runs/${runs[0]}/status.toml" && ! grep -q "queued" "$tmp/s/runs/${runs[0]}/status.toml"' \
  "the failed run's status is as it was"
((fail == 0)) || { cat "$tmp"/*.out; tail -n 30 "$d"/*.log; for f in "$tmp"/s/slurm/*.out; do echo "== $f"; tail -n 5 "$f"; done; }
exit $fail
