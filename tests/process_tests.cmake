# Tests that cross processes over LCM. Each runs its processes in a private
# network namespace (launch_scripts/netns.sh) so that no packet leaves the
# machine.
add_test(NAME e2e_tiny_scene_live_and_replay
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/e2e_tiny.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
# (140 s beside the Python tests and two study runs; more load took it past 300 s in its second replay)
set_tests_properties(e2e_tiny_scene_live_and_replay PROPERTIES LABELS process TIMEOUT 600)

# Cage-relative measures, F_s, alpha_2 and bond breaking (tests/cage_relative.sh):
# the tiny scene's against brute force (cages from scipy), resumed bit for bit.
add_test(NAME cage_relative_tiny
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cage_relative.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(cage_relative_tiny PROPERTIES LABELS process TIMEOUT 300)

add_test(NAME run_scene_refuses_bad_scene
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bad_scene.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(run_scene_refuses_bad_scene PROPERTIES LABELS process TIMEOUT 60)

# No command writes over results it did not write for the same purpose:
# each launch script refuses such a destination, unchanged, and --fresh
# moves it aside intact; a run that fails at run time exits 1, said
# (tests/data_safety.sh).
add_test(NAME launch_scripts_keep_data
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/data_safety.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(launch_scripts_keep_data PROPERTIES LABELS process TIMEOUT 180)

add_test(NAME checkpoint_resume_bit_for_bit
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/checkpoint_resume.sh ${PROJECT_SOURCE_DIR} $<TARGET_FILE_DIR:sim_node>)
set_tests_properties(checkpoint_resume_bit_for_bit PROPERTIES LABELS process TIMEOUT 300)

# Engine stress test (bench/stress_engine.cpp): a short run of all three
# cases in the default suite; under the label `stress`
# (ctest --test-dir build -L stress) 10^9 collisions for each of the two
# inelastic cases (8-12 minutes each on one core, measured with an earlier engine)
# and 10^8 for the elastic energy-drift case (about 1 minute).
add_test(NAME stress_engine_short COMMAND stress_engine --collisions 5e6)
set_tests_properties(stress_engine_short PROPERTIES LABELS engine TIMEOUT 600)
foreach(c 0 1)
  add_test(NAME stress_engine_1e9_case${c} COMMAND stress_engine --collisions 1e9 --case ${c})
  set_tests_properties(stress_engine_1e9_case${c} PROPERTIES LABELS stress TIMEOUT 7200)
endforeach()
add_test(NAME stress_engine_elastic_1e8 COMMAND stress_engine --collisions 1e8 --case 2)
set_tests_properties(stress_engine_elastic_1e8 PROPERTIES LABELS stress TIMEOUT 3600)

# The study runner, local executor: studies/tiny.toml end to end, skipped
# when run again, an interrupted study resumed to the same results bit for
# bit, changed and invalid studies refused, two series sharing one pilot
# (tests/study_local.sh). About 100 s beside the rest of the suite on 2 cores.
add_test(NAME study_local_tiny
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/study_local.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(study_local_tiny PROPERTIES LABELS process TIMEOUT 700)

# Kept frames for the field's tools: run.frames() and the GSD export, read
# back by MDAnalysis (tests/frames_export.sh).
add_test(NAME frames_to_mdanalysis
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/frames_export.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(frames_to_mdanalysis PROPERTIES LABELS process TIMEOUT 120)

# The results archive on studies/tiny.toml: entries written as runs complete,
# checked against the runs; the same analysis from the archive as from the
# study directory; a study resumed from its archive alone; corrupted,
# unlisted and half-written entries never read (tests/study_archive.sh).
add_test(NAME study_archive_tiny
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/study_archive.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(study_archive_tiny PROPERTIES LABELS process TIMEOUT 400)

# The study runner, Slurm executor, against a real throwaway single-host
# Slurm cluster in a private network namespace (tests/slurm_study.sh): every
# run equals the local executor's bit for bit.
add_test(NAME study_slurm_tiny
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slurm_study.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(study_slurm_tiny PROPERTIES LABELS process TIMEOUT 600)

# A run longer than its Slurm time limit completes through requeues
# (tests/slurm_requeue.sh) and equals the local executor's run. Label long:
# out of the default suite (140 s), run with `ctest -L long`.
add_test(NAME study_slurm_requeue
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slurm_requeue.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(study_slurm_requeue PROPERTIES LABELS "process;long" TIMEOUT 900)

# Prepared states (sim_node --prepare-only, system.initial_state): runs from
# one equal the runs that compress themselves, bit for bit; bad states refused.
add_test(NAME prepared_state_bit_for_bit
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/prepared_state.sh ${PROJECT_SOURCE_DIR} $<TARGET_FILE_DIR:sim_node>)
set_tests_properties(prepared_state_bit_for_bit PROPERTIES LABELS process TIMEOUT 300)

# The Q(t) fit over its stated range follows a real run's data, is stable
# when the range shifts by a lag, and has jackknife errors (tests/q_fit.sh).
add_test(NAME q_fit_follows_the_data
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/q_fit.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(q_fit_follows_the_data PROPERTIES LABELS process TIMEOUT 120)

# Hostile input (tests/hostile.sh, tests/hostile_publisher.cpp): during a
# real tiny run every class of malformed or foreign message on every
# channel; no process dies, every one is dropped and counted, the results
# equal a clean run's bit for bit; a forged "done" does not end a node
# early; two runs at once on one bus do not cross.
add_executable(hostile_publisher hostile_publisher.cpp)
target_link_libraries(hostile_publisher PRIVATE dynhet_lcmtypes dynhet_common)
add_test(NAME hostile_messages
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/hostile.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR} $<TARGET_FILE:hostile_publisher>)
set_tests_properties(hostile_messages PROPERTIES LABELS process TIMEOUT 300)
# State only moves forward (hostile.sh state): the run's own state messages
# replayed without the key (those of equilibration in production, each
# node's halfway and after its "done", the sim's after its "done") while
# the recorder is slowed to fall a pacing window behind: complete, equal to
# a clean run bit for bit, every copy counted stale, nothing genuine lost.
add_test(NAME hostile_state_forward
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/hostile.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR} $<TARGET_FILE:hostile_publisher> state)
set_tests_properties(hostile_state_forward PROPERTIES LABELS process TIMEOUT 300)

# Mutated scenes (tests/fuzz_scenes.py, 400 with a fixed seed): each is
# refused by sim_node --check with a message or runs (private bus).
add_test(NAME fuzz_scenes
  COMMAND ${PROJECT_SOURCE_DIR}/launch_scripts/netns.sh /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/fuzz_scenes.py
          $<TARGET_FILE:sim_node> ${PROJECT_SOURCE_DIR} 400)
set_tests_properties(fuzz_scenes PROPERTIES LABELS process TIMEOUT 300)

# A full disk (tests/full_disk.sh: a 12 MB tmpfs in a private mount
# namespace): the recorder stops writing, keeps run.h5 readable and marked
# incomplete with ENOSPC named; a checkpoint on a full disk names ENOSPC.
# Runs that outlive their processes (tests/kill_resume.sh): SIGKILL of random
# processes at random times, during a part's write, SIGTERM of the whole
# group, a corrupted cut, a full disk; every resumed run.h5 equals the
# uninterrupted run's.
add_test(NAME kill_resume
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/kill_resume.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(kill_resume PROPERTIES LABELS process TIMEOUT 600)

add_test(NAME full_disk
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/full_disk.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(full_disk PROPERTIES LABELS process TIMEOUT 120)

# Flow control (tests/stopped_node.sh): a node stopped for 4 s loses no
# frame; the sim waits for it (sim_node --pace-nodes).
add_test(NAME stopped_node_loses_nothing
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/stopped_node.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(stopped_node_loses_nothing PROPERTIES LABELS process TIMEOUT 120)

# Logs of several runs (tests/replay_runs.sh): replay.sh --list, --run-id,
# bit for bit; a log that lacks frames is said to and replays incomplete.
add_test(NAME replay_runs_from_one_log
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/replay_runs.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(replay_runs_from_one_log PROPERTIES LABELS process TIMEOUT 300)

# Every cross-run fit of the study analysis against synthetic studies with
# known parameters: recovered within its jackknife error over seeds, and
# the error honest (tests/test_study_fits.py).
add_test(NAME study_fits_synthetic
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/test_study_fits.py)
# 94 s beside two study runs and a build; 120 s was reached beside the
# kill_resume test as well.
set_tests_properties(study_fits_synthetic PROPERTIES LABELS unit TIMEOUT 300)

# LCM's GUI log player through logplayer.sh on Xvfb: --inputs plays exactly
# the log's inputs (tests/logplayer_gui.sh).
add_test(NAME logplayer_gui
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/logplayer_gui.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(logplayer_gui PROPERTIES LABELS process TIMEOUT 180)

# Two hosts as two network namespaces joined by a veth pair: the sim in one
# (--bus lan --role sim), nodes and recorder in the other; complete, no
# frame lost, equal to the one-host run bit for bit (tests/two_hosts.sh).
add_test(NAME two_hosts_veth
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/two_hosts.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(two_hosts_veth PROPERTIES LABELS process TIMEOUT 180)

# Flow control inside a node (tests/slow_node.sh): the s4 node slowed to
# 0.15 s a frame, its receive thread queuing what the computation has not
# reached and the sim pacing on it: complete, 0 frames lost, equal to an
# unslowed run bit for bit.
add_test(NAME slow_node_loses_nothing
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slow_node.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(slow_node_loses_nothing PROPERTIES LABELS process TIMEOUT 120)

# Without flow control frames are lost, and each node names the cause it
# saw (tests/loss_named.sh): a full queue, or its socket's overflow while
# it was stopped.
add_test(NAME lost_frames_name_their_cause
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/loss_named.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(lost_frames_name_their_cause PROPERTIES LABELS process TIMEOUT 120)

# The recorder keeping every frame, stopped for 5 s mid-run
# (tests/stopped_recorder.sh): the sim waits for it (its own status, node
# "recorder"); complete, every frame in run.h5.
add_test(NAME stopped_recorder_loses_nothing
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/stopped_recorder.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(stopped_recorder_loses_nothing PROPERTIES LABELS process TIMEOUT 120)

# The pressure sim_node prints agrees with high-precision published data
# (event-chain Monte Carlo, Li et al. 2022) for elastic monodisperse disks
# at small N within 3 combined standard errors (bench/pressure_reference.py;
# the N = 72 point resolves the 1/N of either other temperature convention:
# docs/analysis.md, "Which temperature").
add_test(NAME pressure_matches_published_small_n
  COMMAND bash -c "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/bench/pressure_reference.py --build ${CMAKE_BINARY_DIR} --check 3 --port 7796 --n 72 --phi 0.65 --time 40000 --seeds 2 && /usr/bin/python3 ${PROJECT_SOURCE_DIR}/bench/pressure_reference.py --build ${CMAKE_BINARY_DIR} --check 3 --port 7796 --n 224 --phi 0.67 --time 20000 && /usr/bin/python3 ${PROJECT_SOURCE_DIR}/bench/pressure_reference.py --build ${CMAKE_BINARY_DIR} --check 3 --port 7796 --n 870 --phi 0.67 --time 5000")
set_tests_properties(pressure_matches_published_small_n PROPERTIES LABELS process TIMEOUT 300)

# tcpq, LCM's TCP hub (tests/tcpq_runs.sh): the tiny scene 5 times (twice
# with run_scene.sh --bus tcpq, three times on one hub carrying a foreign
# publisher's junk), each complete with 0 frames lost and equal to a udpm
# run bit for bit; every process closes its connection without a reset, so
# its last messages are delivered (dynhet/lcm_exit.hpp).
add_test(NAME tcpq_runs_complete
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tcpq_runs.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(tcpq_runs_complete PROPERTIES LABELS process TIMEOUT 180)

# LCM's own player, unfiltered (tests/logplayer_full.sh): a tiny run's whole
# log (old results included) played with lcm-logplayer into a listening
# recorder, alone and with live nodes: complete, one series per result
# (steps strictly increasing, those of the live run), equal to the live run.
add_test(NAME logplayer_full_log
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/logplayer_full.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(logplayer_full_log PROPERTIES LABELS process TIMEOUT 120)

# tcpq: the hub killed mid-run (tests/tcpq_hub_death.sh): no process aborts
# on LCM's closed socket (dynhet::handle_timeout); each says the connection
# is gone and exits 1; run.h5 is closed, incomplete, with the reason.
add_test(NAME tcpq_hub_death_ends_every_process_cleanly
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tcpq_hub_death.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(tcpq_hub_death_ends_every_process_cleanly PROPERTIES LABELS process TIMEOUT 120)

# The Python package's own unit tests (pytest, Debian's python3-pytest):
# the run reader, the study model, the fits, the row-by-row restatement.
add_test(NAME python_unit
  COMMAND /usr/bin/python3 -m pytest -q -p no:cacheprovider ${CMAKE_CURRENT_SOURCE_DIR}/python)
# The package asks this build's sim_node for resolved scenes (dynhet.scene).
# (80 s alone, 127 s beside e2e_tiny and two study runs)
set_tests_properties(python_unit PROPERTIES LABELS unit TIMEOUT 300 ENVIRONMENT BUILD_DIR=${CMAKE_BINARY_DIR})

# launch_scripts/reproduce.sh, the recipe of the reproduction from nothing:
# every study it names dry-runs, the sum is theirs, bad input refused.
add_test(NAME reproduce_dry
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/reproduce_dry.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(reproduce_dry PROPERTIES LABELS process TIMEOUT 120)
# Re-analysis of a recorded run (tests/reanalyse.sh): replay.sh --analysis
# at the recorded settings equals the live run.h5 bit for bit; other cutoffs
# and cage-relative add their groups, the a = 0.6 results unchanged; what
# decided the frames is refused by name, nothing written.
add_test(NAME replay_reanalyse
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/reanalyse.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(replay_reanalyse PROPERTIES LABELS process TIMEOUT 300)
# docs/reproduction.md and docs/finite_size.md against results/: their text
# regenerated from the committed archive must equal the committed documents.
add_test(NAME docs_from_results
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/docs_from_results.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(docs_from_results PROPERTIES LABELS process TIMEOUT 300)
# Each archive of results/ analysed on its own, as run_study.sh does when a
# study's runs are done: no step fails.
add_test(NAME archives_analyse_alone
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/archives_alone.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(archives_analyse_alone PROPERTIES LABELS process TIMEOUT 300)
