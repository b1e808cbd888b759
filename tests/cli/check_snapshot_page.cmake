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

# --hide, --stage and --eye reach the page (issue #21): with the sail hidden and the toolbar off,
# the shaded picture (no legend) is the background alone (a few hundred bytes); the sail before its deformation steps and
# the sail seen from another side are pictures of their own (not the same bytes).
get_filename_component(dir ${PNG} DIRECTORY)
set(hidden ${dir}/sail_hidden.png)
set(shown ${dir}/sail_bare.png)
set(before ${dir}/sail_before.png)
set(above ${dir}/sail_above.png)
foreach(shot "hidden;--hide;sail" "shown" "before;--stage;before" "above;--eye;0;0;1")
  list(POP_FRONT shot name)
  execute_process(COMMAND ${CLAYFORM} snapshot ${DIR} --png ${${name}} --width 320 --height 200
                          --mode shaded --bare ${shot}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "clayform snapshot ${shot} exited ${rc}:\n${out}${err}")
  endif()
  file(SIZE ${${name}} ${name}_size)
endforeach()
math(EXPR limit "${shown_size} / 5")
if(NOT hidden_size LESS limit)
  message(FATAL_ERROR "--hide sail: ${hidden_size} bytes, not the background alone (shown: ${shown_size})")
endif()
file(SHA256 ${shown} shown_hash)
file(SHA256 ${before} before_hash)
file(SHA256 ${above} above_hash)
if(shown_hash STREQUAL before_hash OR shown_hash STREQUAL above_hash)
  message(FATAL_ERROR "--stage before or --eye 0 0 1 drew the same picture as the default")
endif()
execute_process(COMMAND ${CLAYFORM} snapshot ${DIR} --png ${hidden} --hide jib
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "no surface 'jib'.*its surfaces are sail")
  message(FATAL_ERROR "--hide jib: exit ${rc} (expected 2), stderr '${err}'")
endif()
message(STATUS "hidden ${hidden_size}, shown ${shown_size} bytes")
