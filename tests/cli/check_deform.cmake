# `clayform deform` on example 01's STEP file (2 faces: a bicubic hood and a rational torus
# patch) with the taper of tests/cli/recipes/flare.json: the whole model (faces, edges, vertices)
# deformed exactly and written as STEP, IGES and a .glb preview; and the --help of every command.
# Arguments: -DCLAYFORM=... -DDIR=<example 01 output> -DRECIPE=... -DWORK=...
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CLAYFORM} deform ${DIR}/sample.step --recipe ${RECIPE} --out ${WORK}/out
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "2 deformation stacks \\(flare, shrink\\); name one with --deformation")
  message(FATAL_ERROR "deform without --deformation: exit ${rc}, stderr '${err}'")
endif()
if(EXISTS ${WORK}/out)
  message(FATAL_ERROR "a failed deform left ${WORK}/out behind")
endif()
execute_process(COMMAND ${CLAYFORM} deform ${DIR}/sample.step --recipe ${RECIPE} --deformation flare
                        --out ${WORK}/out --progress
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clayform deform exited ${rc}:\n${out}${err}")
endif()
foreach(expect "read [^\n]*sample.step: 2 bodies" "deformed by flare: 2 faces: 2 exact, 0 refit, 0 untouched; 8 edges: 8 exact" "read back valid")
  if(NOT out MATCHES "${expect}")
    message(FATAL_ERROR "clayform deform: expected '${expect}' in the progress lines:\n${out}")
  endif()
endforeach()
foreach(file sample.step sample.igs sample.glb report.json view/manifest.json)
  if(NOT EXISTS ${WORK}/out/${file})
    message(FATAL_ERROR "clayform deform: ${file} missing in ${WORK}/out")
  endif()
endforeach()
execute_process(COMMAND ${CLAYFORM} info ${WORK}/out/sample.step OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT out MATCHES "2 faces, max degree [0-9]+, [0-9]+ control points, valid \\(BRepCheck\\)" OR NOT out MATCHES "#1 degree \\([0-9]+, [0-9]+\\), [0-9]+ x [0-9]+ control points, rational")
  message(FATAL_ERROR "clayform info on the deformed file (exit ${rc}):\n${out}")
endif()
# --profile: an unknown receiver fails at once, naming the profiles; "exact" keeps the faces
# exact and says so in report.json.
execute_process(COMMAND ${CLAYFORM} deform ${DIR}/sample.step --recipe ${RECIPE} --deformation flare
                        --out ${WORK}/nope --profile alias
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "no receiver profile \"alias\"; the profiles: exact, opencascade, catia, class_a, bicubic")
  message(FATAL_ERROR "deform --profile alias: exit ${rc}, stderr '${err}'")
endif()
execute_process(COMMAND ${CLAYFORM} deform ${DIR}/sample.step --recipe ${RECIPE} --deformation flare
                        --out ${WORK}/exact --profile exact --quiet
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
file(READ ${WORK}/exact/report.json report)
if(NOT rc EQUAL 0 OR NOT report MATCHES "\"profile\": *\"exact\"" OR NOT report MATCHES "\"faces_exact\": *2")
  message(FATAL_ERROR "deform --profile exact: exit ${rc}:\n${out}${err}")
endif()
foreach(cmd run validate deform info)
  execute_process(COMMAND ${CLAYFORM} ${cmd} --help OUTPUT_VARIABLE out RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "Usage:")
    message(FATAL_ERROR "clayform ${cmd} --help: exit ${rc}:\n${out}")
  endif()
endforeach()
execute_process(COMMAND ${CLAYFORM} --help OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT out MATCHES "Exit codes: 0 success")
  message(FATAL_ERROR "clayform --help: exit ${rc}:\n${out}")
endif()
# Usage errors (a missing required option, an unknown one) exit 1, as --help says.
foreach(args "run" "run x.json" "deform x.step --out y" "info a b c" "--frobnicate")
  separate_arguments(list UNIX_COMMAND "${args}")
  execute_process(COMMAND ${CLAYFORM} ${list} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 1)
    message(FATAL_ERROR "clayform ${args}: exit ${rc} (expected 1, usage):\n${out}${err}")
  endif()
endforeach()
