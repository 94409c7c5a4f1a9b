# Tests that cross processes over LCM. Each runs its processes in a private
# network namespace (launch_scripts/netns.sh) so that no packet leaves the
# machine.
add_test(NAME e2e_tiny_scene_live_and_replay
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/e2e_tiny.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(e2e_tiny_scene_live_and_replay PROPERTIES LABELS process TIMEOUT 300)

add_test(NAME run_scene_refuses_bad_scene
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/bad_scene.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(run_scene_refuses_bad_scene PROPERTIES LABELS process TIMEOUT 60)

add_test(NAME checkpoint_resume_bit_for_bit
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/checkpoint_resume.sh ${PROJECT_SOURCE_DIR} $<TARGET_FILE_DIR:sim_node>)
set_tests_properties(checkpoint_resume_bit_for_bit PROPERTIES LABELS process TIMEOUT 300)
