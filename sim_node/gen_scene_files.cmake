# What only repeats the scene's description (common/scene_keys.cpp), written
# by the sim_node just built: the default scene resolved, as the Python
# package's module _scene.py (into python/dynhet/, which runs from the source
# tree; ignored by git), and the reference of every key (a test compares it
# with docs/scenes.md). Arguments: -DSIM= -DPY= -DDOC=
execute_process(COMMAND ${SIM} - --resolved INPUT_FILE /dev/null OUTPUT_VARIABLE defaults
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sim_node - --resolved failed: ${err}")
endif()
string(FIND "${defaults}" "'''" quotes)
if(NOT quotes EQUAL -1)
  message(FATAL_ERROR "the resolved default scene holds ''', which _scene.py cannot quote")
endif()
file(WRITE ${PY}.tmp "\"\"\"Generated at build time by sim_node --resolved from the C++ description of the
scene (common/scene_keys.cpp, the defaults of common/include/dynhet/scene.hpp,
the formulas of model.hpp): do not edit. dynhet.scene reads it.\"\"\"

DEFAULTS_TOML = r'''${defaults}'''
")
file(RENAME ${PY}.tmp ${PY})
execute_process(COMMAND ${SIM} --scene-reference OUTPUT_VARIABLE reference RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sim_node --scene-reference failed")
endif()
file(WRITE ${DOC} "${reference}")
