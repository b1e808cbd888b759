# `clayform info` on a 2 KB IGES sheet whose corner weight is 1e6 (tests/cli/files/, written by
# write_iges from a bilinear patch): the volume integration of its face ran 2^40 deep, for ever,
# in the main process (issue #36). A sheet has no volume, so since issue #39 its faces are not
# integrated at all (WiZ WORX's surface model was refused for a sheet face that did not
# converge): it must read within seconds, exit 0, valid, with no volume. That a solid's face which
# does not converge is refused, naming the face, within its budget, is tested by
# tests/brep/model_test.cpp ("volume_mm3 ends on a face with an extreme weight").
# Arguments: -DCLAYFORM=... -DFILE=...
string(TIMESTAMP start "%s")
execute_process(COMMAND ${CLAYFORM} info ${FILE} OUTPUT_VARIABLE out ERROR_VARIABLE err
  RESULT_VARIABLE rc TIMEOUT 60)
string(TIMESTAMP end "%s")
math(EXPR seconds "${end} - ${start}")
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "clayform info ${FILE}: exit '${rc}' (expected 0):\n${out}${err}")
endif()
if(NOT out MATCHES "1 face, max degree 1, 4 control points, valid \\(BRepCheck\\)\n" OR
   out MATCHES "volume")
  message(FATAL_ERROR "clayform info ${FILE}: expected a valid sheet without a volume:\n${out}")
endif()
if(seconds GREATER 45)  # sanitized builds are several times slower
  message(FATAL_ERROR "clayform info ${FILE} took ${seconds} s (expected seconds)")
endif()
message(STATUS "clayform info ${FILE}: exit 0 in ${seconds} s")
