# Analysis kernel tests: in-process, brute force and synthetic data.
foreach(name test_displacement test_displacement_distribution test_chi4 test_s4 test_s4_average test_lag_interpolation test_clusters
             test_fits test_cage test_bonds test_self_scattering)
  add_executable(${name} ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
  target_link_libraries(${name} PRIVATE dynhet_analysis GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 30 PROPERTIES LABELS unit)
endforeach()
