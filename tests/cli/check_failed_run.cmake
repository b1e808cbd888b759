# A run that fails writes nothing into --out and says why on stderr (issue #18: a bottle whose
# export read back invalid left every file in --out, exit 6, with the reason on stdout only).
# recipes/readback-invalid.json is valid, but its one degree-25 span reads back INVALID.
# Arguments: -DCLAYFORM=... -DRECIPE=... -DWORK=...
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/out)
execute_process(COMMAND ${CLAYFORM} validate ${RECIPE} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clayform validate ${RECIPE}: exit ${rc} (expected 0, a valid recipe):\n${out}${err}")
endif()
execute_process(COMMAND ${CLAYFORM} run ${RECIPE} --out ${WORK}/out OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 6)
  message(FATAL_ERROR "clayform run: exit ${rc} (expected 6, exchange):\n${out}${err}")
endif()
if(NOT err MATCHES "clayform: exchange: export rough: rough.step reads back INVALID \\(BRepCheck\\), so nothing was written"
   OR NOT err MATCHES "problem: surface #0: BRepCheck")
  message(FATAL_ERROR "clayform run: the reason is not on stderr:\nstdout:\n${out}\nstderr:\n${err}")
endif()
if(out MATCHES "INVALID")
  message(FATAL_ERROR "clayform run: the failure is reported on stdout:\n${out}")
endif()
file(GLOB left ${WORK}/out/* ${WORK}/out/.* ${WORK}/.out.clayform-*)
if(left)
  message(FATAL_ERROR "clayform run failed but left files behind: ${left}")
endif()
