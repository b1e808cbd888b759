# Runs `clayform info` on the STEP and IGES files of example 01 and checks what it prints against
# the surfaces the example built (a bicubic 8 x 6 hood and an exact rational torus patch), plus
# --version, the exit code for a file of the wrong kind, how the filleted block's faces meet
# (examples/models/block.step, -DMODELS), and --strict on a file that needs healing (-DCAD).
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
# How the faces meet: the filleted block's 42 shared edges, its fillets tangent to their sides
# (the angle below 1e-9 degrees) with the curvature jumping from 1/5 to 0 (closed forms).
execute_process(COMMAND ${CLAYFORM} info ${MODELS}/block.step
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
foreach(expect "continuity: 42 shared edges: gap <= [0-9.e-]+ mm, angle <= 90 deg"
               "smooth joins \\(angle < 10 deg\\), worst first:"
               "angle [0-9.]+e-1[0-9] deg, curvature jump 0.2 /mm \\(relative 1\\)")
  if(NOT rc EQUAL 0 OR NOT out MATCHES "${expect}")
    message(FATAL_ERROR "clayform info block.step (exit ${rc}): expected '${expect}' in:\n${out}${err}")
  endif()
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
# Alias's pcurves leave their surfaces' domains: healed by default (exit 0, listed), listed as
# problems with --strict (exit 3, the model is not valid).
set(alias ${CAD}/alias_autostudio96_k1_bspline_solid_ap214.stp)
execute_process(COMMAND ${CLAYFORM} info ${alias} OUTPUT_VARIABLE out ERROR_VARIABLE err
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT out MATCHES "healed: pulled 14 pcurves into their surfaces' domains")
  message(FATAL_ERROR "clayform info (healing) on Alias's key: exit ${rc}:\n${out}${err}")
endif()
execute_process(COMMAND ${CLAYFORM} info --strict ${alias} OUTPUT_VARIABLE out ERROR_VARIABLE err
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 3 OR NOT out MATCHES "the pcurve leaves the surface's domain" OR
   out MATCHES "pulled 14 pcurves")
  message(FATAL_ERROR "clayform info --strict on Alias's key: exit ${rc}:\n${out}${err}")
endif()
