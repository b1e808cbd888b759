# `clayform info` on a 2 KB IGES sheet whose corner weight is 1e6 (tests/cli/files/, written by
# write_iges from a bilinear patch): the volume integration of its face ran 2^40 deep, for ever,
# in the main process (issue #36). It must end within seconds with exit 8 (tolerance not met)
# and say which face did not converge and why.
# Arguments: -DCLAYFORM=... -DFILE=...
string(TIMESTAMP start "%s")
execute_process(COMMAND ${CLAYFORM} info ${FILE} OUTPUT_VARIABLE out ERROR_VARIABLE err
  RESULT_VARIABLE rc TIMEOUT 60)
string(TIMESTAMP end "%s")
math(EXPR seconds "${end} - ${start}")
if(NOT rc STREQUAL "8")
  message(FATAL_ERROR "clayform info ${FILE}: exit '${rc}' (expected 8, tolerance not met):\n${out}${err}")
endif()
if(NOT err MATCHES "the volume did not converge on 1 face\\(s\\) \\(0\\) within its budget")
  message(FATAL_ERROR "clayform info ${FILE}: no message naming the face:\n${err}")
endif()
if(seconds GREATER 45)  # sanitized builds are several times slower
  message(FATAL_ERROR "clayform info ${FILE} took ${seconds} s (expected seconds)")
endif()
message(STATUS "clayform info ${FILE}: exit 8 in ${seconds} s: ${err}")
