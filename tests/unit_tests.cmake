# Unit tests: in-process, no bus.
foreach(name test_collision test_engine test_theory test_scene test_schedule test_chunking test_overlap)
  add_executable(${name} ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
  target_link_libraries(${name} PRIVATE dynhet_engine dynhet_analysis dynhet_common GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
endforeach()
target_compile_definitions(test_scene PRIVATE DYNHET_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# Checkpoint parts and cuts (state_archive, cut): round trips, refusals.
add_executable(test_state_archive ${CMAKE_CURRENT_SOURCE_DIR}/test_state_archive.cpp)
target_link_libraries(test_state_archive PRIVATE dynhet_analysis dynhet_common GTest::gtest_main)
gtest_discover_tests(test_state_archive DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
# The authenticated bus: key files, tags, replays (bus_auth, bus.hpp).
add_executable(test_bus_auth ${CMAKE_CURRENT_SOURCE_DIR}/test_bus_auth.cpp)
target_link_libraries(test_bus_auth PRIVATE dynhet_common dynhet_lcmtypes GTest::gtest_main)
gtest_discover_tests(test_bus_auth DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
# The bounded queue between a node's receive thread and its compute thread.
add_executable(test_inbox ${CMAKE_CURRENT_SOURCE_DIR}/test_inbox.cpp)
target_link_libraries(test_inbox PRIVATE dynhet_node dynhet_common GTest::gtest_main)
gtest_discover_tests(test_inbox DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
# --help of every launch script prints its usage and starts nothing
# (tests/script_help.sh).
add_test(NAME launch_scripts_help
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/script_help.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(launch_scripts_help PROPERTIES LABELS unit TIMEOUT 120)
# The sim's side of checkpoint cuts over memq:// (sim_node/cut_coordinator.cpp).
add_executable(test_cut_coordinator ${CMAKE_CURRENT_SOURCE_DIR}/test_cut_coordinator.cpp
  ${PROJECT_SOURCE_DIR}/sim_node/cut_coordinator.cpp)
target_include_directories(test_cut_coordinator PRIVATE ${PROJECT_SOURCE_DIR}/sim_node)
target_link_libraries(test_cut_coordinator PRIVATE dynhet_common dynhet_lcmtypes GTest::gtest_main)
gtest_discover_tests(test_cut_coordinator DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
# Re-analysis scenes (dynhet/reanalysis.hpp): merge, refusals by name, the
# recorded text back at the original settings.
add_executable(test_reanalysis ${CMAKE_CURRENT_SOURCE_DIR}/test_reanalysis.cpp)
target_link_libraries(test_reanalysis PRIVATE dynhet_common GTest::gtest_main)
gtest_discover_tests(test_reanalysis DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
# Quoted errors against the scatter of independent seeds of the real system
# (in-process engine and kernels): tau_alpha(t0) per origin, xi(t) per lag.
add_executable(test_seed_errors ${CMAKE_CURRENT_SOURCE_DIR}/test_seed_errors.cpp)
target_link_libraries(test_seed_errors PRIVATE dynhet_engine dynhet_analysis GTest::gtest_main)
gtest_discover_tests(test_seed_errors DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit TIMEOUT 120)
