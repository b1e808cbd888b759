# Issue #42: the workbench's features in freecadcmd (workbench_test.py), CASES of it.
# Arguments: -DFREECADCMD=... -DSCRIPT=<workbench_test.py> -DWORKBENCH=<freecad/Clayform>
#            -DPYTHONPATH=<built package> -DSOURCE=<repository> -DCLAYFORM=<clayform command>
#            -DWORK=<dir> -DCASES=<comma-separated>
foreach(v FREECADCMD SCRIPT WORKBENCH PYTHONPATH SOURCE CLAYFORM WORK CASES)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_workbench.cmake: -D${v}=... missing")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/home)
# freecadcmd keeps its settings under $HOME: a private one, so tests leave no trace there.
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env HOME=${WORK}/home CLAY_WORKBENCH=${WORKBENCH}
          CLAY_PYTHONPATH=${PYTHONPATH} CLAY_SOURCE=${SOURCE} CLAY_CLAYFORM=${CLAYFORM}
          CLAY_WORK=${WORK} CLAY_CASES=${CASES} PYTHONDONTWRITEBYTECODE=1
          ${FREECADCMD} ${SCRIPT}
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "workbench_test.py (${CASES}): exit ${rc}")
endif()
