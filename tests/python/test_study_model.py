"""dynhet.study.model on study files written here: the points of the
series with their overrides, each run's scene with run lengths in units of
its tau_alpha, and every problem of a bad file named at once."""
import math
import os

import pytest

from dynhet.study.model import Study, StudyError

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")

GOOD = """
[study]
name = "t"
[scene.system]
n_particles = 300
[[series]]
restitution = [0.9]
packing_fraction = [0.60, 0.70]
seed = [1, 2]
[[series]]
restitution = [0.8]
packing_fraction = [0.70]
seed = [1]
[[override]]
when = { packing_fraction = 0.70, restitution = 0.8 }
set = { system = { n_particles = 1024 } }
[run_length]
tau_alpha = "pilot"
equilibration_tau = 10.0
origin_spacing_tau = 1.0
origins = 8
lag_min_tau = 0.02
lag_max_tau = 30.0
"""


def study(tmp_path, text):
    p = tmp_path / "s.toml"
    p.write_text(text)
    return Study(str(p), base_scene=os.path.join(ROOT, "scenes", "tiny.toml"))


def test_points_overrides_and_run_lengths(tmp_path):
    s = study(tmp_path, GOOD)
    pts = s.points()
    assert len(pts) == 5
    big = [p for p in pts if p["restitution"] == 0.8]
    assert len(big) == 1 and big[0]["n_particles"] == 1024          # the override shows in the point
    assert len({s.run_name(p) for p in pts}) == 5                    # names are unique
    p = [q for q in pts if q["packing_fraction"] == 0.6 and q["seed"] == 2][0]
    sc = s.scene(p, tau=2.0)
    assert sc["system"]["packing_fraction"] == 0.6 and sc["system"]["seed"] == 2
    assert sc["run"]["equilibration_time"] == 20.0
    sch = sc["schedule"]
    assert (sch["origins"], sch["origin_spacing"], sch["lag_min"], sch["lag_max"]) == (8, 2.0, 0.04, 60.0)


def test_every_problem_is_named(tmp_path):
    bad = GOOD.replace('tau_alpha = "pilot"', 'tau_alpha = "guess"').replace("lag_max_tau = 30.0", "lag_max_tau = 0.01") \
              .replace("[study]", "[study]\ncolour = 1\nrun_plots = \"no\"").replace("packing_fraction = 0.70, restitution = 0.8",
                                                               "packing_fraction = 0.75, restitution = 0.8")
    with pytest.raises(StudyError) as e:
        study(tmp_path, bad)
    msg = str(e.value)
    assert 'run_length.tau_alpha: value \'guess\' is not allowed' in msg
    assert "run_length.lag_min_tau: must be smaller than run_length.lag_max_tau" in msg
    assert "override[0].when.packing_fraction: value 0.75 is not on axis" in msg
    assert "colour" in msg
    assert "study.run_plots: value 'no' must be true or false" in msg


def test_run_lengths_in_the_cage_relative_tau_alpha(tmp_path):
    # unit = "tau_alpha_cr": every run (and its pilot) computes the
    # cage-relative observables, and its tau is read from overlap_cr.
    s = study(tmp_path, GOOD.replace('tau_alpha = "pilot"', 'tau_alpha = "pilot"\nunit = "tau_alpha_cr"'))
    p = s.points()[0]
    assert s.tau_group() == "overlap_cr"
    assert s.scene(p, tau=2.0)["observables"]["cage_relative"] is True
    pilot = s.scene(p, tau=2.0, pilot=True)
    assert pilot["observables"]["cage_relative"] is True and pilot["observables"]["compute"] == ["overlap"]
    assert study(tmp_path, GOOD).tau_group() == "overlap"
    with pytest.raises(StudyError) as e:
        study(tmp_path, GOOD.replace('tau_alpha = "pilot"', 'tau_alpha = "pilot"\nunit = "tau_cr"'))
    assert "run_length.unit: value 'tau_cr' is not allowed" in str(e.value)


def test_the_dry_run_scales_its_estimate_by_what_complete_runs_cost():
    from dynhet.study.index import measured_ratio
    ratios, overall = measured_ratio([(1024, 10.0, 15.0), (1024, 30.0, 45.0), (4096, 100.0, 110.0)])
    assert ratios == {1024: 1.5, 4096: 1.1}
    assert abs(overall - 170.0 / 140.0) < 1e-12
    assert measured_ratio([]) == ({}, None)


def test_a_study_dir_takes_the_same_study_with_other_comments_and_refuses_another(tmp_path):
    from dynhet.study.rundir import StudyDir
    out = tmp_path / "out"
    StudyDir(study(tmp_path, GOOD), str(out)).claim()
    # comments and spacing are not the study: the same directory resumes it
    StudyDir(study(tmp_path, "# a note on the cost\n" + GOOD.replace("seed = [1, 2]", "seed = [1,  2]  # two")),
             str(out)).claim()
    with pytest.raises(StudyError, match="differs from the study"):
        StudyDir(study(tmp_path, GOOD.replace("seed = [1, 2]", "seed = [1, 2, 3]")), str(out)).claim()


def test_the_executors_take_the_longest_run_first(tmp_path):
    # Longest-processing-time first: on a few cores the study's wall time is
    # set by its longest run, which must not start last behind short ones.
    # The estimates are the dry run's, from each run's own scene.
    from dynhet.study.index import run_estimates, run_order
    from dynhet.study.rundir import StudyDir
    text = GOOD.replace("lag_max_tau = 30.0", "lag_max_tau = 30.0\ntau_guess = [[0.6, 1.0], [0.7, 5.0]]")
    sd = StudyDir(study(tmp_path, text), str(tmp_path / "out"))
    sd.claim()
    pts = sd.study.points()
    est = run_estimates(sd)
    order = run_order(sd, pts, est)
    costs = [est[sd.study.run_name(p)] for p in order]
    assert costs == sorted(costs, reverse=True) and costs[0] > costs[-1]
    assert order[0]["n_particles"] == 1024                # the big, slow run starts first
    assert [p["packing_fraction"] for p in order[-2:]] == [0.6, 0.6]
    same = [p for p in order if p["packing_fraction"] == 0.6]
    assert [p["seed"] for p in same] == [1, 2]            # equal estimates keep the study's order
    # --order shortest: the reverse, equal estimates still in the study's order
    short = run_order(sd, pts, est, "shortest")
    assert [est[sd.study.run_name(p)] for p in short] == sorted(costs)
    assert [p["seed"] for p in short if p["packing_fraction"] == 0.6] == [1, 2]
    # --first: the matching runs ahead of all others, pattern by pattern, each
    # group in the --order; the rest as before
    names = lambda seq: [sd.study.run_name(p) for p in seq]
    big = [n for n in names(pts) if "_n1024_" in n]
    firsts = run_order(sd, pts, est, "shortest", ["*_n1024_*", "phi0.6000_*"])
    assert names(firsts[:len(big)]) == names(sorted((p for p in pts if "_n1024_" in sd.study.run_name(p)),
                                                    key=lambda p: est[sd.study.run_name(p)]))
    rest = firsts[len(big):]
    assert all(sd.study.run_name(p).startswith("phi0.6000_") for p in rest[:2])
    assert names(rest[2:]) == [n for n in names(short) if n not in names(firsts[:len(big) + 2])]
    with pytest.raises(StudyError, match="--first 'phi0.9_\\*' matches none"):
        run_order(sd, pts, est, "shortest", ["phi0.9_*"])
    # interpolated run lengths need the low densities first, whatever they cost
    sd = StudyDir(study(tmp_path, text.replace('tau_alpha = "pilot"', 'tau_alpha = "interpolate"')),
                  str(tmp_path / "out2"))
    sd.claim()
    order = run_order(sd, sd.study.points(), est)
    assert [p["packing_fraction"] for p in order[:2]] == [0.6, 0.6]
    with pytest.raises(StudyError, match="interpolates its run lengths"):
        run_order(sd, sd.study.points(), est, "longest", ["*"])


def test_an_interrupted_run_is_ordered_by_what_its_checkpoint_has_left(tmp_path):
    # Two runs of the same system, one stopped 90% through: with --order
    # shortest (and within a --first group) it goes before the fresh one,
    # its estimate being what is left after the point it resumes from (its
    # newest whole checkpoint cut; its checkpoint before the frames; or,
    # with neither, or no scene.toml, the start: it starts over).
    from dynhet.study.index import plan, run_estimates, run_estimates_left, run_order
    from dynhet.study.rundir import StudyDir, write_status
    from dynhet.scene import resolved
    text = GOOD.replace("lag_max_tau = 30.0", "lag_max_tau = 30.0\ntau_guess = [[0.6, 1.0], [0.7, 5.0]]")
    sd = StudyDir(study(tmp_path, text), str(tmp_path / "out"))
    sd.claim()
    pts = sd.study.points()
    pair = [p for p in pts if p["packing_fraction"] == 0.70 and p["restitution"] == 0.9]
    assert [p["seed"] for p in pair] == [1, 2]
    full, left = run_estimates(sd), run_estimates_left(sd)
    assert left == full                                              # nothing started: all of each is left
    name = sd.study.run_name
    d = sd.run_dir(pair[1])                                          # seed 2, 90% through, then stopped
    os.makedirs(d, exist_ok=True)
    write_status(d, {"state": "interrupted"})
    run = resolved([sc for p, sc, *_ in plan(sd) if p == pair[1]][0])["run"]
    end = run["equilibration_time"] + run["production_time"]
    with open(os.path.join(d, "sim_node.log"), "w") as f:
        f.write(f"[production ] t={0.9 * end:.6g} /{end:.6g}  phi=0.7000  coll/s=1e+06  T=0.9  Z=9  "
                "frames 10/12  ETA 0:01:00\n")
    assert run_estimates_left(sd)[name(pair[1])] == full[name(pair[1])]   # no checkpoint: it starts over
    open(os.path.join(d, "checkpoint_before_frames.h5"), "w").close()
    assert run_estimates_left(sd)[name(pair[1])] == full[name(pair[1])]   # no scene.toml: it starts over too
    open(os.path.join(d, "scene.toml"), "w").close()
    assert math.isclose(run_estimates_left(sd)[name(pair[1])],      # the production from its start
                        full[name(pair[1])] * run["production_time"] / end, rel_tol=1e-9)
    os.makedirs(os.path.join(d, "checkpoints", "cut-12"))
    open(os.path.join(d, "checkpoints", "cut-12", "WHOLE"), "w").close()
    left = run_estimates_left(sd)                                    # from the cut: what the sim last said
    assert math.isclose(left[name(pair[1])], 0.1 * full[name(pair[1])], rel_tol=1e-3)
    assert left[name(pair[0])] == full[name(pair[0])]
    order = [name(p) for p in run_order(sd, pair, left, "shortest", ["phi0.7000_eps0.900_*"])]
    assert order == [name(pair[1]), name(pair[0])]                  # the nearly finished one first
    # a run that resumes goes before one that starts afresh, whatever the estimates and the order:
    assert [name(p) for p in run_order(sd, pair, full, "shortest")] == [name(pair[1]), name(pair[0])]
    assert [name(p) for p in run_order(sd, pair, left, "longest")] == [name(pair[1]), name(pair[0])]
    write_status(d, {"state": "queued", "previous_state": "interrupted", "job": 7})   # a Slurm resubmission
    assert math.isclose(run_estimates_left(sd)[name(pair[1])], 0.1 * full[name(pair[1])], rel_tol=1e-3)
    write_status(d, {"state": "failed"})                            # a failed run starts over
    assert run_estimates_left(sd)[name(pair[1])] == full[name(pair[1])]
    assert [name(p) for p in run_order(sd, pair, full, "shortest")] == [name(pair[0]), name(pair[1])]  # by the estimates


def test_a_size_not_yet_piloted_is_estimated_from_the_pilots_of_the_same_system(tmp_path):
    # A pilot runs min(N, pilot_particles) particles: the pilots of N = 4096
    # and 16384 ran the same 2048-particle system as N = 65536's will, so
    # the dry run estimates 65536 from them (times the pilot margin the run
    # will take), not from tau_guess; a pilot of N = 1024 (1024 particles)
    # does not count.
    from dynhet.study.index import plan
    from dynhet.study.rundir import StudyDir, write_status
    text = GOOD.replace("packing_fraction = [0.60, 0.70]\n", "packing_fraction = [0.60, 0.70]\nn_particles = [65536]\n") \
               .replace("lag_max_tau = 30.0", "lag_max_tau = 30.0\ntau_guess = [[0.6, 1.0], [0.7, 1.0]]")
    sd = StudyDir(study(tmp_path, text), str(tmp_path / "out"))
    sd.claim()
    p = [q for q in sd.study.points() if q["packing_fraction"] == 0.7 and q["restitution"] == 0.9][0]
    assert p["n_particles"] == 65536 and sd.study.run_length["pilot_particles"] == 2048
    assert sd.guess(p) == (1.0, "the study's tau_guess")
    for name, n, phi, tau in (("a", 4096, 0.6, 2.0), ("b", 16384, 0.7, 8.0), ("c", 1024, 0.7, 100.0)):
        d = tmp_path / "out" / "pilots" / name
        d.mkdir(parents=True)
        write_status(str(d), {"state": "complete", "tau_alpha": tau, "packing_fraction": phi,
                              "series": [0.9, "neighbours", n]})
    got = sd.finished_taus(p)
    assert [ph for ph, _ in got] == [0.6, 0.7] and math.isclose(got[0][1], 2.0) and math.isclose(got[1][1], 8.0)
    tau, src = sd.guess(p)
    assert math.isclose(tau, 8.0) and src == "interpolated from finished points"
    row = [r for r in plan(sd) if r[0] == p][0]
    assert math.isclose(row[2], 8.0 * 1.2) and row[3].startswith("guess: interpolated from finished points x 1.2")


def test_beyond_the_finished_points_the_guess_follows_the_tau_guess_table(tmp_path):
    # scale.toml's case: pilots at 0.78 and 0.80 only. A line in ln tau
    # through them, extrapolated down to 0.76, gave 3.6 where the table
    # puts a third of 0.78's; the table's shape through the nearest
    # finished point gives 77 x 30 / 90.
    from dynhet.study.rundir import StudyDir, write_status
    text = GOOD.replace("packing_fraction = [0.60, 0.70]", "packing_fraction = [0.76, 0.78, 0.79, 0.80, 0.81]") \
               .replace("lag_max_tau = 30.0", "lag_max_tau = 30.0\ntau_guess = [[0.76, 30.0], [0.78, 90.0], "
                                                "[0.79, 230.0], [0.80, 900.0]]")
    sd = StudyDir(study(tmp_path, text), str(tmp_path / "out"))
    sd.claim()
    pts = {q["packing_fraction"]: q for q in sd.study.points() if q["restitution"] == 0.9 and q["seed"] == 1}
    for name, phi, tau in (("a", 0.78, 77.0), ("b", 0.80, 1657.0)):
        d = tmp_path / "out" / "pilots" / name
        d.mkdir(parents=True)
        write_status(str(d), {"state": "complete", "tau_alpha": tau, "packing_fraction": phi,
                              "series": [0.9, "neighbours", 300]})
    tau, src = sd.guess(pts[0.76])
    assert math.isclose(tau, 77.0 * 30.0 / 90.0) and src.endswith("finished point at phi = 0.78")
    tau, src = sd.guess(pts[0.79])                      # between them: ln tau linear in phi
    assert math.isclose(tau, math.sqrt(77.0 * 1657.0)) and src == "interpolated from finished points"
    tau, src = sd.guess(pts[0.81])                      # above: the table's own end, extrapolated
    assert math.isclose(tau, 1657.0 * (900.0 * (900.0 / 230.0)) / 900.0)
    assert src.endswith("finished point at phi = 0.8")
    assert sd.guess(pts[0.76], finished=False) == (30.0, "the study's tau_guess")


def test_the_dry_runs_time_left_counts_only_what_a_running_run_has_not_simulated(tmp_path):
    from dynhet.study.index import share_done
    d = tmp_path / "run"
    d.mkdir()
    sim_time = 19890.0 + 21880.0                                       # equilibration + production
    assert share_done(str(d), "running", sim_time) == 0.0        # no progress line yet
    (d / "sim_node.log").write_text(
        "[equilibrate] t=7830      /1.989e+04  phi=0.8000  coll/s=1.36e+06  T=0.86  Z=29.6  frames 0/212  ETA 4:57:36\n")
    # equilibration's line names the end of equilibration; the share is of both phases (one clock)
    assert math.isclose(share_done(str(d), "running", sim_time), 7830.0 / 41770.0)
    assert math.isclose(share_done(str(d), "interrupted", sim_time), 7830.0 / 41770.0)
    for state in ("failed", "pending", "too_short", "complete"):   # these start over, or are not left
        assert share_done(str(d), state, sim_time) == 0.0


def test_a_running_run_is_described_from_its_sims_last_progress_line(tmp_path):
    from dynhet.study.progress import describe, sim_progress
    d = tmp_path / "run"
    d.mkdir()
    assert sim_progress(str(d)) is None and "starting" in describe("r", str(d))
    (d / "sim_node.log").write_text(
        "sim_node: run 1\n"
        "[equilibrate] t=1836      /1.989e+04  phi=0.8000  coll/s=7.91e+05  T=0.8661  Z=30.06  frames 0/212  ETA 10:06:45\n"
        "sim_node: checkpoint: cut 2725 after frame 90 at t=27260 (sim part 0.9 MB in 0.00 s)\n"
        "\r[production ] t=2.726e+04 /4.177e+04  phi=0.8000  coll/s=1.27e+06  T=0.8705  Z=29.37  frames 91/212  "
        "ETA 0:33:52   \r[production ] t=2.73e+04 /4.177e+04  phi=0.8000  coll/s=1.2e+06  T=0.87  Z=29.4  "
        "frames 92/212  ETA 0:33:10   ")
    p = sim_progress(str(d))
    assert p == {"phase": "production", "t": 27300.0, "end": 41770.0, "frames": 92, "frames_total": 212,
                 "eta": "0:33:10"}
    assert describe("r", str(d)) == ("  r: production t = 2.73e+04 of 4.177e+04 (65% of the phase), frames 92/212, "
                                     "the sim's ETA 0:33:10")


def test_an_earlier_attempts_log_is_not_the_running_runs_progress(tmp_path):
    import os
    import time as _time
    from dynhet.study.progress import describe
    d = tmp_path / "run"
    d.mkdir()
    log = d / "sim_node.log"
    log.write_text("[done       ] t=18 /18  phi=0.6000  coll/s=0  T=1.06  Z=6.1  frames 56/56  ETA 0:00:00\n")
    old = _time.time() - 100
    os.utime(log, (old, old))
    assert "starting" in describe("r", str(d), since=_time.time() - 10)   # the run began after that line
    assert "done t = 18 of 18" in describe("r", str(d), since=old - 1)


def test_pilots_of_other_sizes_count_only_where_pilots_set_run_lengths(tmp_path):
    from dynhet.study.rundir import StudyDir, write_status
    text = GOOD.replace("packing_fraction = [0.60, 0.70]\n", "packing_fraction = [0.60, 0.70]\nn_particles = [65536]\n")
    for mode, counted in (("pilot", 1), ("interpolate", 0)):
        sd = StudyDir(study(tmp_path, text.replace('tau_alpha = "pilot"', f'tau_alpha = "{mode}"')),
                      str(tmp_path / mode))
        sd.claim()
        d = tmp_path / mode / "pilots" / "a"
        d.mkdir(parents=True)
        write_status(str(d), {"state": "complete", "tau_alpha": 2.0, "packing_fraction": 0.6,
                              "series": [0.9, "neighbours", 4096]})
        p = [q for q in sd.study.points() if q["restitution"] == 0.9][0]
        assert len(sd.finished_taus(p)) == counted, mode


def test_the_study_ends_when_its_last_slot_does():
    from dynhet.study.progress import eta_seconds, study_eta
    assert eta_seconds("6:52:54") == 6 * 3600 + 52 * 60 + 54 and eta_seconds("?") is None
    # one slot busy for 7 h with the longest run, the other takes the queue (3 h, 2 h, 1 h): 7 h
    h = 3600.0
    assert study_eta([7 * h, 0.5 * h], [3 * h, 2 * h, 1 * h], 2) == 7 * h
    # the queue alone on two free slots: 4 | 2 + 2 -> 4 h
    assert study_eta([], [4 * h, 2 * h, 2 * h], 2) == 4 * h
    assert study_eta([], [], 2) == 0.0


def test_a_resumed_run_keeps_the_cpu_of_earlier_attempts_and_counts_a_killed_one():
    """The status a new attempt writes at its start carries the CPU of the
    earlier attempts; one left "running" (killed before it could record its
    own: the whole machine stopped) loses only its own, and is counted."""
    from dynhet.study.runner import carried_cpu, running_status
    # what the new attempt writes at its start, before anything can kill it
    st = running_status({"state": "running", "attempts": 2, "cpu_s": 5118.6}, "cut", "pilot x 1.2")
    assert st["state"] == "running" and st["attempts"] == 3 and st["cpu_s"] == 5118.6 and st["cpu_unrecorded"] == 1
    # stopped by a signal: recorded its CPU, nothing lost
    assert carried_cpu({"state": "interrupted", "cpu_s": 5118.6}, "cut") == (5118.6, 0)
    # killed while running: its status still carries the attempts before it (written at its start)
    assert carried_cpu({"state": "running", "cpu_s": 5118.6}, "cut") == (5118.6, 1)
    assert carried_cpu({"state": "running", "cpu_s": 10.0, "cpu_unrecorded": 1}, "cut") == (10.0, 2)
    # starting over: the result costs only what the new attempt costs
    assert carried_cpu({"state": "failed", "cpu_s": 99.0}, None) == (0.0, 0)


def test_max_attempts_counts_run_lengths_not_resumptions():
    """A run stopped and resumed goes on with its schedule: however many
    times it was started, it has been given one run length, so a too short
    result may still be run again with a longer one (max_attempts bounds the
    lengths). Only a start after a too short result gives a new length."""
    from dynhet.study.runner import running_status
    first = running_status({}, None, "pilot x 1.2")
    assert first["attempts"] == 1 and first["schedules"] == 1
    resumed = first
    for _ in range(4):  # four stops, each resumed from its cut
        resumed = running_status(dict(resumed, state="interrupted"), "cut", "pilot x 1.2")
    assert resumed["attempts"] == 5 and resumed["schedules"] == 1
    longer = running_status(dict(resumed, state="too_short"), None, "1.3 x the tau_alpha of the previous, too short attempt")
    assert longer["attempts"] == 6 and longer["schedules"] == 2
    # started over with the same length: interrupted before its first checkpoint, or after a failure
    assert running_status(dict(longer, state="interrupted"), None, "pilot")["schedules"] == 2
    assert running_status(dict(longer, state="queued", previous_state="running"), None, "pilot")["schedules"] == 2
    assert running_status(dict(longer, state="failed"), None, "pilot")["schedules"] == 2
    # a status written before schedules were counted: one length if it ran at all
    assert running_status({"state": "too_short", "attempts": 3}, None, "1.3 x")["schedules"] == 2
    assert running_status({"state": "interrupted", "attempts": 3}, "cut", "pilot")["schedules"] == 1
    assert running_status({"state": "interrupted", "attempts": 3}, None, "pilot")["schedules"] == 1


def test_a_run_queued_again_on_slurm_goes_by_what_it_was_before():
    """A Slurm submission writes "queued" over the status and keeps the state
    before in previous_state: a run killed while running counts its lost
    attempt, a failed one is started over (do_run goes by effective_state)."""
    from dynhet.study.runner import carried_cpu, effective_state
    assert effective_state({"state": "queued", "previous_state": "running"}) == "running"
    assert effective_state({"state": "queued", "previous_state": "failed"}) == "failed"
    assert effective_state({"state": "queued"}) == "queued"          # never started
    assert effective_state({"state": "interrupted", "previous_state": "failed"}) == "interrupted"
    assert carried_cpu({"state": "queued", "previous_state": "running", "cpu_s": 7.0}, "cut") == (7.0, 1)


def test_a_run_whose_origins_lie_closer_than_its_tau_alpha_is_too_short():
    """Origins planned one estimated tau_alpha apart: a run that measures a
    longer tau_alpha has correlated tau_alpha(t0), no steadiness check, and
    is too short for its plan; one at or below its estimate is not; a plan
    of origins closer than tau_alpha on purpose is not judged by this."""
    from dynhet.study.runner import origins_too_close
    sc = {"schedule": {"origin_spacing": 124.0}}
    assert origins_too_close(sc, 157.0, 1.0)
    assert not origins_too_close(sc, 120.0, 1.0) and not origins_too_close(sc, 124.0, 1.0)
    assert not origins_too_close(sc, 157.0, 0.5)
    assert not origins_too_close(sc, float("nan"), 1.0) and not origins_too_close({}, 157.0, 1.0)


def test_on_a_new_machine_the_dry_run_sees_the_archive_as_the_run_will(tmp_path, capsys):
    # The run directories are gone (a new machine) and the results archive
    # holds one run and a pilot: the dry run counts the run complete at its
    # archived CPU time, with nothing left to run, and estimates the others
    # from the archived pilot, as running the study would (it restores both
    # from the archive) -- not as pending runs at the study's tau_guess.
    from dynhet.archive import Archive
    from dynhet.study.index import dry_run, plan
    from dynhet.study.rundir import StudyDir
    s = study(tmp_path, GOOD.replace("lag_max_tau = 30.0", "lag_max_tau = 30.0\ntau_guess = [[0.6, 1.0], [0.7, 1.0]]"))
    arch = Archive(str(tmp_path / "results"))
    arch.claim(s)
    done = [q for q in s.points() if q["packing_fraction"] == 0.6 and q["seed"] == 1][0]
    idx = arch.read()
    os.makedirs(os.path.join(arch.dir, "runs"), exist_ok=True)
    with open(os.path.join(arch.dir, "runs", "x.h5.gz"), "wb") as f:
        f.write(b"x" * 5)
    idx["runs"][s.run_name(done)] = {"file": "runs/x.h5.gz", "bytes": 5, "sha256": "0", "tau_alpha": 3.0,
                                     "tau_estimate": 3.6, "tau_source": "pilot x 1.2", "cpu_s": 1234.0}
    lost = [q for q in s.points() if q["packing_fraction"] == 0.6 and q["seed"] == 2][0]
    idx["runs"][s.run_name(lost)] = {"file": "runs/gone.h5.gz", "bytes": 5, "sha256": "0", "tau_alpha": 3.0}
    arch._write_index(idx)
    arch.add_pilot("p07", {"state": "complete", "tau_alpha": 5.0, "packing_fraction": 0.7,
                           "series": [0.9, "neighbours", 300]})
    sd = StudyDir(s, str(tmp_path / "out"), archive=arch.dir)
    rows = {s.run_name(r[0]): r for r in plan(sd)}
    assert rows[s.run_name(done)][4] == "complete" and math.isclose(rows[s.run_name(done)][2], 3.6)
    other = [q for q in s.points() if q["packing_fraction"] == 0.7 and q["restitution"] == 0.9][0]
    assert [ph for ph, _ in sd.finished_taus(other)] == [0.6, 0.7]
    assert math.isclose(sd.guess(other)[0], 5.0)
    assert rows[s.run_name(lost)][4] == "pending"   # an entry whose file is gone is not taken for complete
    assert not os.path.exists(sd.run_dir(done))  # nothing written
    # an archive of another study: the dry run refuses it, as the run does
    other = study(tmp_path, GOOD.replace("origins = 8", "origins = 6"))
    with pytest.raises(StudyError, match="archives another study"):
        plan(StudyDir(other, str(tmp_path / "out2"), archive=arch.dir))
    dry_run(sd)
    out = capsys.readouterr().out
    line = [ln for ln in out.splitlines() if ln.startswith(s.run_name(done))][0]
    assert line.split()[1] == "complete" and "0:20:34" in line
