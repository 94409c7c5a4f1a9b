#!/usr/bin/env bash
# The study runner on the local executor (launch_scripts/run_study.sh):
# studies/tiny.toml end to end; the same command again skips every run; a
# study stopped by SIGTERM in a run's production (a second SIGTERM during
# the stop is said, not raised) is resumed from that run's checkpoint and
# ends with the results of the uninterrupted study, bit for bit; a changed
# study file and an invalid one are refused with messages naming the
# problem. Each run is on its own private bus (run_scene.sh).
set -euo pipefail
root=$1 build=$2
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'pkill -TERM -f "study.py run .*$tmp" 2>/dev/null || true; rm -rf "$tmp"' EXIT
study=(bash "$root/launch_scripts/run_study.sh" --no-build)
# Study a's analysis draws its figures (tests/check_study_analysis.py checks
# them); every later study's analysis is of numbers compared, not figures:
# --no-figures, the text and study.h5 alone.
nofig=(--no-figures)
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }

DYNHET_STUDY_PROGRESS_EVERY=1 "${study[@]}" "$root/studies/tiny.toml" --out "$tmp/a" --jobs 2 >"$tmp/a.out" 2>&1 ||
  { cat "$tmp/a.out"; exit 1; }
check 'grep -q "4 of 4 runs complete, 0 failed" "$tmp/a.out"' "tiny study: 4 of 4 runs complete"
check '! ls "$tmp"/a/runs/*/*.png "$tmp"/a/pilots/*/*.png >/dev/null 2>&1 && grep -q -- "--no-plots" "$tmp"/a/runs/*/run_scene.log' \
  "run_plots = false: no run or pilot drew its PNGs (run_scene.sh --no-plots)"
# Progress while runs go on (every second here): a line per running run, from its sim's own progress line.
check 'grep -Eq "^  phi0\.[0-9]+_eps0\.900_n300_seed[12]: (equilibrate|production|done) t = .* of the phase\), frames [0-9]+/[0-9]+, the sim.s ETA" "$tmp/a.out"' \
  "progress lines name each running run's phase, time, frames and ETA"
# Every run's schedule came from a pilot's tau_alpha (or, if the run came out
# too short for it, from 1.3 times the run's own), and is long enough for
# the tau_alpha it measured: equilibration 10 estimates >= 9 tau_alpha, and
# origins one estimate apart at least its tau_alpha apart.
check '/usr/bin/python3 -c "
import tomllib, sys
runs = tomllib.load(open(\"$tmp/a/index.toml\", \"rb\"))[\"runs\"].values()
ok = all(r[\"tau_source\"] in (\"pilot x 1.2\", \"1.3 x the tau_alpha of the previous, too short attempt\")
         and 10 * r[\"tau_estimate\"] >= 9 * r[\"tau_alpha\"] and r[\"tau_estimate\"] >= r[\"tau_alpha\"] for r in runs)
sys.exit(0 if ok and len(runs) == 4 else 1)"' "every run's schedule came from a pilot (or its own too short attempt), says so, is >= 9 tau_alpha long, its origins >= tau_alpha apart"
check '[[ $(ls "$tmp"/a/runs/*/run.h5 | wc -l) == 4 ]]' "each run has its run.h5"
# Each run has a lag at its best tau_alpha estimate (schedule.extra_lags),
# and its clusters are taken at its measured tau_alpha (interpolated between
# the lags around it; at the lag nearest it where it is not bracketed).
check '/usr/bin/python3 -c "
import tomllib, sys, h5py, math
d = \"$tmp/a\"
runs = tomllib.load(open(d + \"/index.toml\", \"rb\"))[\"runs\"]
worst = 0
for r in runs.values():
    sc = tomllib.load(open(d + \"/\" + r[\"path\"] + \"/scene.toml\", \"rb\"))
    margin = 1.2 if r[\"tau_source\"].startswith(\"pilot\") else 1.3
    if sc[\"schedule\"][\"extra_lags\"] != [round(r[\"tau_estimate\"] / margin, 6)]:
        sys.exit(1)
    f = h5py.File(d + \"/\" + r[\"path\"] + \"/run.h5\", \"r\")
    lags = f[\"observables/overlap/a0.6/lag_time\"][()]
    tau = r[\"tau_alpha\"]
    best = min(lags, key=lambda t: abs(math.log(t / tau)))
    lag = float(f[\"observables/clusters/a0.6/lag/value\"][-1])
    at = tau if int(f[\"observables/clusters/a0.6/lag_lo/value\"][-1]) >= 0 else best
    if abs(lag - at) > 1e-6 * at:
        sys.exit(1)
print(\"ok\")"' "each run has a lag at its tau_alpha estimate, and its clusters are at tau_alpha (or the lag nearest it)"
# One prepared state per (N, phi, seed): the 4 runs and 2 pilots (N = 300, first seed) need 5.
check '[[ $(ls "$tmp"/a/states/*.h5 | wc -l) == 5 ]] && grep -q "initial_state = .*states/n300_phi0.6_r1.43_seed1.h5" "$tmp"/a/runs/phi0.6000_eps0.900_n300_seed1/scene.toml' \
  "each system compressed once (5 prepared states for 4 runs and 2 pilots), the runs start from them"

# The study analysis ran at the end (run_study.sh): study.h5, figures and
# the reproduction table, checked against the runs themselves.
check 'grep -q "analyse_study: .* rows" "$tmp/a.out"' "the study analysis ran when the runs were done"
check '! grep -q "analyse_study: FAILED\|Traceback" "$tmp/a.out"' "no step of the study analysis failed"
/usr/bin/python3 "$root/tests/check_study_analysis.py" "$tmp/a" || fail=1
bash "$root/launch_scripts/analyse_study.sh" "$tmp/nothing" >"$tmp/n.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "is not a study directory nor a results archive: no index.toml" "$tmp/n.out"' "analysing a directory that is no study: a bad argument, said (exit $rc)"

stamp=$(stat -c %Y "$tmp"/a/runs/*/status.toml | sort | tail -1)
sleep 1
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/a" --jobs 2 "${nofig[@]}" >"$tmp/a2.out" 2>&1
check 'grep -q "4 of 4 runs complete already (skipped)" "$tmp/a2.out"' "run again: every run skipped"
check '[[ $(stat -c %Y "$tmp"/a/runs/*/status.toml | sort | tail -1) == "$stamp" ]]' "run again: no run touched"

# Stop the study (SIGTERM, as a shutdown does) once the first run is in production.
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/b" --jobs 1 "${nofig[@]}" >"$tmp/b.out" 2>&1 &
runner=$!
for _ in $(seq 600); do
  ls "$tmp"/b/runs/*/checkpoint_before_frames.h5 >/dev/null 2>&1 && grep -qs "frames" "$tmp"/b/runs/*/sim_node.log &&
    [[ -n $(grep -ls "production" "$tmp"/b/runs/*/sim_node.log) ]] && break
  sleep 0.1
done
kill -TERM "$runner"
# A second SIGTERM while the runs write their checkpoints (Ctrl-C twice, a
# shutdown that repeats itself) is said, and the stop goes on.
for _ in $(seq 200); do grep -q "stopping the runs" "$tmp/b.out" && break; sleep 0.02; done
kill -TERM "$runner" 2>/dev/null || true
wait "$runner" && rc=0 || rc=$?
check '[[ $rc == 75 ]]' "stopped study exits 75, resumable (got $rc)"
check '! grep -q "Traceback" "$tmp/b.out"' "a second SIGTERM during the stop: no traceback"
check 'grep -qs "state = \"interrupted\"" "$tmp"/b/runs/*/status.toml' "the stopped run is marked interrupted"
stopped=$(grep -ls "state = \"interrupted\"" "$tmp"/b/runs/*/status.toml | head -1)
cpu_before=$(sed -n 's/^cpu_s = //p' "$stopped")
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/b" --jobs 2 "${nofig[@]}" >"$tmp/b2.out" 2>&1 || { cat "$tmp/b2.out"; exit 1; }
cpu_after=$(sed -n 's/^cpu_s = //p' "$stopped") cpu_attempt=$(sed -n 's/^cpu_s_attempt = //p' "$stopped")
check 'awk -v b="$cpu_before" -v a="$cpu_after" -v t="$cpu_attempt" "BEGIN { exit !(b > 0 && t > 0 && (a - b - t) ^ 2 < 1e-12) }"' \
  "the resumed run's CPU is its two attempts' ($cpu_before + $cpu_attempt = $cpu_after s)"
check 'grep -qE "was interrupted; resuming from (checkpoint cut [0-9]+( \\(its sim last said: (equilibrate|production) t = )?|.*checkpoint_before_frames.h5)" "$tmp/b2.out"' \
  "run again: the interrupted run resumes from its last checkpoint cut (or, before any, from its state before the frames)"
check 'grep -q "4 of 4 runs complete, 0 failed" "$tmp/b2.out"' "run again: 4 of 4 complete"
check 'grep -q "analyse_study: .* rows" "$tmp/b2.out" && [[ -f $tmp/b/study.h5 && -f $tmp/b/reproduction.md ]] &&
  ! ls "$tmp"/b/figures/*.png >/dev/null 2>&1' "run_study.sh --no-figures: the analysis wrote study.h5 and its table, no figure"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/a" "$tmp/b" || fail=1
# A run marked failed is run again from the start (run_scene.sh --fresh, its
# old cuts and file gone), not resumed from a cut that would fail again,
# and comes out as before, bit for bit.
failed_run=$(ls -d "$tmp"/b/runs/*/ | head -1)
sed -i 's/^state = .*/state = "failed"/' "$failed_run/status.toml"
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/b" --jobs 2 "${nofig[@]}" >"$tmp/b3.out" 2>&1 || { cat "$tmp/b3.out"; exit 1; }
check 'grep -q "failed before .*running it again" "$tmp/b3.out" && grep -q "3 of 4 runs complete already" "$tmp/b3.out" &&
  tail -n +"$(grep -n "^# " "$failed_run/run_scene.log" | tail -1 | cut -d: -f1)" "$failed_run/run_scene.log" | head -1 | grep -q -- "--fresh" &&
  grep -q "4 of 4 runs complete, 0 failed" "$tmp/b3.out"' \
  "a run marked failed is run again from the start (--fresh) and completes"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/a" "$tmp/b" || fail=1

# prepared_states = "equilibrated": every run starts from an equilibrated
# state of its dynamics and ends bit for bit like the runs of study a.
sed -e "s|\"../scenes/tiny.toml\"|\"$root/scenes/tiny.toml\"\nprepared_states = \"equilibrated\"|" \
  "$root/studies/tiny.toml" >"$tmp/eq.toml"
"${study[@]}" "$tmp/eq.toml" --out "$tmp/e" --jobs 2 "${nofig[@]}" >"$tmp/e.out" 2>&1 || { cat "$tmp/e.out"; exit 1; }
check '[[ $(grep -l "initial_state = .*states/eq_n.*_t10.h5" "$tmp"/e/runs/*/scene.toml | wc -l) == 4 ]] &&
  grep -q "equilibrated state .* from t = 0 to 10 " "$tmp"/e/states/eq_*.log' \
  "prepared_states = \"equilibrated\": each run starts from its state equilibrated to t = 10"
/usr/bin/python3 "$root/tests/compare_studies.py" "$tmp/a" "$tmp/e" || fail=1

# A changed study file under an existing study directory is refused.
sed -e 's/seed = \[1, 2\]/seed = [1, 2, 3]/' -e "s|\"../scenes/tiny.toml\"|\"$root/scenes/tiny.toml\"|" \
  "$root/studies/tiny.toml" >"$tmp/changed.toml"
"${study[@]}" "$tmp/changed.toml" --out "$tmp/a" >"$tmp/c.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "differs from the study that" "$tmp/c.out"' "a changed study is refused (exit $rc)"

# An invalid study: each problem named with its key, nothing run.
cat >"$tmp/bad.toml" <<TOML
[study]
scene = "$root/scenes/tiny.toml"
nmae = "x"
[axes]
packing_fraction = [0.6, "dense"]
seeds = [1]
[run_length]
tau_alpha = "guess"
TOML
"${study[@]}" "$tmp/bad.toml" --out "$tmp/bad" >"$tmp/bad.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "study.nmae: unknown key" "$tmp/bad.out" && grep -q "axes.packing_fraction" "$tmp/bad.out" &&
  grep -q "axes.seeds: unknown axis" "$tmp/bad.out" && grep -q "run_length.tau_alpha" "$tmp/bad.out"' "an invalid study is refused, every problem named"
check '[[ ! -d $tmp/bad/runs ]]' "an invalid study runs nothing"
# A study whose scene would be refused: named by run and scene key.
printf '[study]\nscene = "%s"\n[axes]\npacking_fraction = [0.6, 0.95]\n' "$root/scenes/tiny.toml" >"$tmp/dense.toml"
"${study[@]}" "$tmp/dense.toml" --out "$tmp/dense" >"$tmp/dense.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 2 ]] && grep -q "phi0.9500.*system.packing_fraction" "$tmp/dense.out"' "a point whose scene sim_node refuses is named before anything runs"
# Two series (N = 300 and 400) whose pilots run the same system (a pilot runs
# min(N, pilot_particles) = 300 particles): the second takes the first's
# tau_alpha instead of running it again, and says so.
sed -e '/^\[\[override\]\]/,$d' -e 's/^seed = \[1, 2\]/seed = [1]\nn_particles = [300, 400]/' \
  -e 's/^packing_fraction = .*/packing_fraction = [0.60]/' -e "s|\.\./scenes/|$root/scenes/|" "$root/studies/tiny.toml" >"$tmp/shared.toml"
"${study[@]}" "$tmp/shared.toml" --out "$tmp/shared" --jobs 1 "${nofig[@]}" >"$tmp/shared.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 0 ]] && grep -q "2 of 2 runs complete, 0 failed" "$tmp/shared.out"' "two series sharing a pilot system: both runs complete"
check '[[ $(ls "$tmp"/shared/pilots/*/run.h5 | wc -l) == 1 ]]' "the shared pilot system ran once (one pilot run.h5)"
check '/usr/bin/python3 -c "
import tomllib, glob, sys
st = {p.split(\"/\")[-2]: tomllib.load(open(p, \"rb\")) for p in glob.glob(\"$tmp/shared/pilots/*/status.toml\")}
ran = [n for n, s in st.items() if s[\"attempts\"] > 0]
took = [n for n, s in st.items() if s.get(\"reused_from\")]
ok = len(st) == 2 and len(ran) == 1 and len(took) == 1 and st[took[0]][\"reused_from\"] == ran[0] \
     and st[took[0]][\"tau_alpha\"] == st[ran[0]][\"tau_alpha\"] and st[took[0]][\"system_key\"] == st[ran[0]][\"system_key\"]
sys.exit(0 if ok else 1)"' "the other series' pilot took its tau_alpha, naming the pilot it came from"
((fail == 0)) || { echo "--- outputs"; cat "$tmp"/*.out; }
exit $fail
