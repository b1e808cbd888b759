# `clayform snapshot` of a run through the real viewer page (viewer/dist): a zebra picture of
# the sail example. Checks the exit code, the PNG signature and size, and that the picture is
# not blank (the page drew the surface before Chromium took it: a PNG of one flat colour
# compresses to a few kilobytes).
# Arguments: -DCLAYFORM=... -DDIR=<a clayform run folder> -DPNG=<output>
file(REMOVE ${PNG})
execute_process(COMMAND ${CLAYFORM} snapshot ${DIR} --png ${PNG} --width 640 --height 400 --mode zebra
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clayform snapshot exited ${rc}:\n${out}${err}")
endif()
file(READ ${PNG} head LIMIT 24 HEX)
if(NOT head MATCHES "^89504e470d0a1a0a0000000d49484452000002800000019")
  message(FATAL_ERROR "${PNG} is not a 640 x 400 PNG: ${head}")
endif()
file(SIZE ${PNG} size)
if(size LESS 20000)
  message(FATAL_ERROR "${PNG} is only ${size} bytes: the page drew nothing")
endif()
message(STATUS "snapshot ${PNG}: ${size} bytes")
