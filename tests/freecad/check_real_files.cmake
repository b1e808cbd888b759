# Issue #39: every file of tests/data/cad read by FreeCAD (scripts/freecad_real_files.py) and by
# Clayform (compare_real_files.py): counts, validity and volumes agree.
# Arguments: -DFREECADCMD=... -DPYTHON=... -DPYTHONPATH=<built package> -DSOURCE=<repository>
#            -DWORK=<dir>
foreach(v FREECADCMD PYTHON PYTHONPATH SOURCE WORK)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_real_files.cmake: -D${v}=... missing")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/home)
# freecadcmd keeps its settings under $HOME: a private one, so tests leave no trace there.
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env HOME=${WORK}/home CLAY_FREECAD_OUT=${WORK}/freecad.json
          ${FREECADCMD} ${SOURCE}/scripts/freecad_real_files.py
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/freecad.json)
  message(FATAL_ERROR "freecad_real_files.py: exit ${rc}\n${out}${err}")
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PYTHONPATH} PYTHONDONTWRITEBYTECODE=1
          ${PYTHON} ${SOURCE}/tests/freecad/compare_real_files.py ${WORK}/freecad.json
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "Clayform's reading differs from FreeCAD's (exit ${rc})")
endif()
