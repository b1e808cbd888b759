# Runs `clayform info` on the STEP and IGES files of example 01 and checks what it prints against
# the surfaces the example built (a bicubic 8 x 6 hood and an exact rational torus patch), plus
# --version and the exit code for a file of the wrong kind.
foreach(file sample.step sample.igs)
  execute_process(COMMAND ${CLAYFORM} info ${DIR}/${file}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "clayform info ${file} exited ${rc}: ${out}${err}")
  endif()
  foreach(expect "2 faces, max degree 3, 57 control points, valid \\(BRepCheck\\)"
                 "body 0: (shell|sheet)[^\n]*, 1 shell, [12] faces? \\([12] trimmed, 0 holes\\)"
                 "#0 degree \\(3, 3\\), 8 x 6 control points, polynomial"
                 "#1 degree \\(2, 2\\), 3 x 3 control points, rational"
                 "u knots 0\\^4 0.2")
    if(NOT out MATCHES "${expect}")
      message(FATAL_ERROR "clayform info ${file}: expected '${expect}' in:\n${out}")
    endif()
  endforeach()
endforeach()
execute_process(COMMAND ${CLAYFORM} --version OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^clayform [0-9]+\\.[0-9]+\\.[0-9]+")
  message(FATAL_ERROR "clayform --version printed '${out}' (exit ${rc})")
endif()
execute_process(COMMAND ${CLAYFORM} info ${DIR}/report.json
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "give a .step/.stp or .igs/.iges file")
  message(FATAL_ERROR "clayform info on a JSON file: exit ${rc}, stderr '${err}'")
endif()
execute_process(COMMAND ${CLAYFORM} info ${DIR}/missing.step
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 5)
  message(FATAL_ERROR "clayform info on a missing file: exit ${rc} (expected 5, i/o), stderr '${err}'")
endif()
