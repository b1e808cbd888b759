# Issue #38's "exact and light" acceptance on a written file, measured by FreeCAD: MODEL deformed
# by RECIPE's non-affine lattice with `clayform deform --profile PROFILE`, then
# edge_continuity.py (FreeCAD's Part module, OCCT's own evaluators) measures the written STEP
# against the source's own figures: BRepCheck valid, no new free edge, every G1 edge of the
# source (normals within 1e-3 deg there: fillets, blends, seams) within G1_DEG (0.016 deg), every
# G2 edge (also a relative curvature jump below 1e-3) within G2_REL (1 %) of curvature.
# Arguments: -DCLAYFORM=... -DFREECADCMD=... -DSCRIPT=<edge_continuity.py> -DMODEL=<.step>
#            -DRECIPE=<.json> -DPROFILE=<name> -DWORK=<dir> [-DG1_DEG=0.016] [-DG2_REL=0.01]
foreach(v CLAYFORM FREECADCMD SCRIPT MODEL RECIPE PROFILE WORK)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_profile.cmake: -D${v}=... missing")
  endif()
endforeach()
if(NOT DEFINED G1_DEG)
  set(G1_DEG 0.016)
endif()
if(NOT DEFINED G2_REL)
  set(G2_REL 0.01)
endif()
get_filename_component(stem ${MODEL} NAME_WE)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/home)
# freecadcmd keeps its settings under $HOME: a private one, so tests leave no trace there.
set(freecad ${CMAKE_COMMAND} -E env HOME=${WORK}/home ${FREECADCMD} ${SCRIPT})

# the source's own figures (which edges are G1 and G2)
execute_process(COMMAND ${freecad} ${MODEL} json=${WORK}/source.json table=0
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/source.json)
  message(FATAL_ERROR "edge_continuity.py on the source ${MODEL}: exit ${rc}\n${out}${err}")
endif()

string(TIMESTAMP t0 "%s")
execute_process(COMMAND ${CLAYFORM} deform ${MODEL} --recipe ${RECIPE} --out ${WORK}/out
                        --profile ${PROFILE} --quiet
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
string(TIMESTAMP t1 "%s")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clayform deform --profile ${PROFILE} ${MODEL}: exit ${rc}\n${out}${err}")
endif()
if(NOT EXISTS ${WORK}/out/${stem}.step)
  message(FATAL_ERROR "clayform deform wrote no ${stem}.step in ${WORK}/out")
endif()

execute_process(COMMAND ${freecad} ${WORK}/out/${stem}.step reference=${WORK}/source.json
                        json=${WORK}/check.json g1_deg=${G1_DEG} g2_rel=${G2_REL}
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
string(TIMESTAMP t2 "%s")
# freecadcmd's banner first: keep the checker's own lines
string(REGEX REPLACE "^.*\n(/[^\n]*: (valid|NOT VALID), )" "\\1" out "${out}")
math(EXPR deform_s "${t1} - ${t0}")
math(EXPR check_s "${t2} - ${t1}")
message(STATUS "${stem} ${PROFILE}: deform ${deform_s} s, FreeCAD check ${check_s} s\n${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${stem}.step written for ${PROFILE} misses issue #38's figures "
                      "(edge_continuity.py exit ${rc}; table in ${WORK}/check.json):\n${out}${err}")
endif()
