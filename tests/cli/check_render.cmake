# Runs `clayform render` on example 01's STEP and IGES files (read as models, meshed by
# brep::tessellate) and checks the pictures: exit 0, a PNG
# signature and the requested size in the IHDR chunk; then the exit codes for a file of the wrong
# kind (2, invalid argument) and a picture in a missing folder (5, i/o).
foreach(file sample.step sample.igs)
  set(png ${DIR}/${file}.png)
  file(REMOVE ${png})
  execute_process(COMMAND ${CLAYFORM} render ${DIR}/${file} --png ${png} --width 320 --height 200 --net
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "2 face\\(s\\), [0-9]+ triangles -> .*\\(320 x 200, [0-9]+ ms\\)")
    message(FATAL_ERROR "clayform render ${file} exited ${rc}: ${out}${err}")
  endif()
  if(NOT EXISTS ${png})
    message(FATAL_ERROR "clayform render ${file}: ${png} was not written")
  endif()
  # PNG signature, then the IHDR chunk: length 13, "IHDR", width and height (big-endian 32 bit).
  file(READ ${png} head LIMIT 24 HEX)
  if(NOT head STREQUAL "89504e470d0a1a0a0000000d4948445200000140000000c8")
    message(FATAL_ERROR "clayform render ${file}: ${png} starts with ${head}, not a 320 x 200 PNG")
  endif()
endforeach()
# A recipe: run, its final surface pictured with its 5 curves drawn over it.
set(png ${DIR}/sail.png)
file(REMOVE ${png})
execute_process(COMMAND ${CLAYFORM} render ${RECIPE} --png ${png} --width 320 --height 200
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT out MATCHES "1 surface\\(s\\), 5 curve\\(s\\) -> .*\\(320 x 200, [0-9]+ ms\\)")
  message(FATAL_ERROR "clayform render ${RECIPE} exited ${rc}: ${out}${err}")
endif()
file(READ ${png} head LIMIT 24 HEX)
if(NOT head STREQUAL "89504e470d0a1a0a0000000d4948445200000140000000c8")
  message(FATAL_ERROR "clayform render ${RECIPE}: ${png} starts with ${head}, not a 320 x 200 PNG")
endif()
# A JSON file that is not a recipe: the recipe's problem, exit 7.
execute_process(COMMAND ${CLAYFORM} render ${DIR}/report.json --png ${DIR}/report.png
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 7 OR NOT err MATCHES "format")
  message(FATAL_ERROR "clayform render on a JSON file that is no recipe: exit ${rc}, stderr '${err}'")
endif()
# A file of another kind: exit 2.
file(WRITE ${DIR}/notes.txt "not a model")
execute_process(COMMAND ${CLAYFORM} render ${DIR}/notes.txt --png ${DIR}/notes.png
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "give a .step/.stp or .igs/.iges file")
  message(FATAL_ERROR "clayform render on a text file: exit ${rc}, stderr '${err}'")
endif()
execute_process(COMMAND ${CLAYFORM} render ${DIR}/sample.step --png ${DIR}/missing/sample.png
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 5 OR NOT err MATCHES "missing/sample.png")
  message(FATAL_ERROR "clayform render into a missing folder: exit ${rc} (expected 5, i/o), stderr '${err}'")
endif()
