# Recorder tests: the H5MD writer's round trip, the run bookkeeping fed
# with synthetic messages, and a writer killed with SIGKILL.
add_executable(test_h5md ${CMAKE_CURRENT_SOURCE_DIR}/test_h5md.cpp)
target_link_libraries(test_h5md PRIVATE dynhet_h5md HDF5::HDF5 GTest::gtest_main)
gtest_discover_tests(test_h5md TEST_PREFIX "h5md/" PROPERTIES LABELS unit)

add_executable(test_recorder_run ${CMAKE_CURRENT_SOURCE_DIR}/test_recorder_run.cpp)
target_link_libraries(test_recorder_run PRIVATE dynhet_run_recorder HDF5::HDF5 GTest::gtest_main)
gtest_discover_tests(test_recorder_run TEST_PREFIX "recorder/" PROPERTIES LABELS unit)

add_executable(h5md_kill_writer ${CMAKE_CURRENT_SOURCE_DIR}/h5md_kill_writer.cpp)
target_link_libraries(h5md_kill_writer PRIVATE dynhet_h5md)
add_test(NAME recorder_kill
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_recorder_kill.sh $<TARGET_FILE:h5md_kill_writer>)
set_tests_properties(recorder_kill PROPERTIES LABELS process TIMEOUT 60)
