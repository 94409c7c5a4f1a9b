# lcm-spy's curve views (spy_plugins/) on a virtual display: tests/spy_plugins.sh
# and its Java checker (tests/spy/), built when the plugins are.
if(TARGET dynhet_spy_plugins)
  include(UseJava)
  set(CMAKE_JAVA_COMPILE_FLAGS -Xlint:all -Werror)
  add_jar(dynhet_spy_check
    SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/spy/dynhet/spycheck/SpyPluginCheck.java
            ${CMAKE_CURRENT_SOURCE_DIR}/spy/dynhet/spycheck/ExpectedCurves.java
            ${CMAKE_CURRENT_SOURCE_DIR}/spy/dynhet/spycheck/SpyLog.java
            ${CMAKE_CURRENT_SOURCE_DIR}/spy/dynhet/spycheck/HostileCases.java
    INCLUDE_JARS dynhet_spy_plugins /usr/share/java/lcm.jar /usr/share/java/jchart2d.jar
                 ${CMAKE_BINARY_DIR}/dynhet_lcmtypes.jar
    OUTPUT_DIR ${CMAKE_BINARY_DIR})
  add_dependencies(dynhet_spy_check dynhet_lcmtypes_jar)
  # spy.sh's lcm-spy finds the four plugins; inside lcm-spy, views opened
  # by double clicks draw a real tiny run's curves live and exactly; every
  # logged result message drawn point for point; hostile messages rejected
  # and counted. Screenshots in build/test_output/spy_plugins/.
  add_test(NAME spy_plugins
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/spy_plugins.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
  set_tests_properties(spy_plugins PROPERTIES LABELS process TIMEOUT 240)
endif()
