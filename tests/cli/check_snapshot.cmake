# clayform snapshot with a stand-in front end (fake_viewer/index.html, which reads the run's
# manifest and draws on a canvas): the plumbing of `clayform run` -> view/ -> server -> headless
# chromium -> PNG, independently of the real viewer. Checks the view folder a run writes, the PNG
# (signature, the requested size in IHDR, more than a blank picture's bytes) and the exit codes:
# 2 for a bad mode, 5 for a folder without view data (snapshot and view). Without
# /usr/bin/chromium, snapshot must fail with exit 5 naming the Debian package.
# -DCLAYFORM=... -DVIEWER=<fake dist> -DWORK=<scratch folder>
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/can.json [=[
{"format": "clayform.recipe", "version": 1, "name": "can",
 "curves": {"profile": {"line": {"from": [30, 0, 0], "to": [30, 0, 80]}}},
 "surfaces": {
   "can": {"revolve": {"profile": "profile", "axis": {"point": [0, 0, 0], "direction": [0, 0, 1]}, "angle": 270}},
   "flared": {"deform": {"surface": "can", "deformation": "flare"}}},
 "deformations": {"flare": [{"kind": "taper", "name": "flare",
   "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]}, "profile": [1, 0.004]}]},
 "exports": {"can": {"surfaces": ["flared", "can"], "formats": ["glb"]}}}
]=])
execute_process(COMMAND ${CLAYFORM} run ${WORK}/can.json --out ${WORK}/run --quiet
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clayform run can.json exited ${rc}: ${out}${err}")
endif()
foreach(f view/manifest.json view/000.bin report.json can.glb)
  if(NOT EXISTS ${WORK}/run/${f})
    message(FATAL_ERROR "clayform run: no ${f} in ${WORK}/run")
  endif()
endforeach()
file(READ ${WORK}/run/view/manifest.json manifest)
string(JSON format GET "${manifest}" format)
string(JSON surfaces LENGTH "${manifest}" surfaces)
string(JSON stages LENGTH "${manifest}" surfaces 0 stages)
if(NOT format STREQUAL "clayform.view" OR NOT surfaces EQUAL 2 OR NOT stages EQUAL 1)
  message(FATAL_ERROR "view/manifest.json: format ${format}, ${surfaces} surfaces, ${stages} stages of the first")
endif()

set(ENV{CLAYFORM_VIEWER_DIR} ${VIEWER})
set(png ${WORK}/shot.png)
set(temp_glob /tmp/clayform-chromium-*)
if(DEFINED ENV{TMPDIR} AND NOT "$ENV{TMPDIR}" STREQUAL "")
  set(temp_glob $ENV{TMPDIR}/clayform-chromium-*)
endif()
file(GLOB before LIST_DIRECTORIES true ${temp_glob})
if(NOT EXISTS /usr/bin/chromium)
  execute_process(COMMAND ${CLAYFORM} snapshot ${WORK}/run --png ${png}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 5 OR NOT err MATCHES "apt-get install chromium")
    message(FATAL_ERROR "clayform snapshot without chromium: exit ${rc} (expected 5), stderr '${err}'")
  endif()
  message(STATUS "no /usr/bin/chromium: checked the error only (apt-get install chromium)")
  return()
endif()
execute_process(COMMAND ${CLAYFORM} snapshot ${WORK}/run --png ${png} --width 320 --height 200 --mode zebra
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc TIMEOUT 90)
if(NOT rc EQUAL 0 OR NOT out MATCHES "zebra view -> .*shot.png \\(320 x 200, [0-9.]+ s\\)")
  message(FATAL_ERROR "clayform snapshot exited ${rc}: ${out}${err}")
endif()
if(NOT EXISTS ${png})
  message(FATAL_ERROR "clayform snapshot: ${png} was not written")
endif()
file(READ ${png} head LIMIT 24 HEX)
if(NOT head STREQUAL "89504e470d0a1a0a0000000d4948445200000140000000c8")
  message(FATAL_ERROR "clayform snapshot: ${png} starts with ${head}, not a 320 x 200 PNG")
endif()
# A blank 320 x 200 picture compresses to a few hundred bytes; bars and text take more.
file(SIZE ${png} size)
if(size LESS 1500)
  message(FATAL_ERROR "clayform snapshot: ${png} has only ${size} bytes; the page drew nothing")
endif()
# no temporary chromium profile left behind
file(GLOB left LIST_DIRECTORIES true ${temp_glob})
if(before)
  list(REMOVE_ITEM left ${before})
endif()
if(left)
  message(FATAL_ERROR "clayform snapshot left temporary folders: ${left}")
endif()

execute_process(COMMAND ${CLAYFORM} snapshot ${WORK}/run --png ${png} --mode wireframe
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "shaded, zebra, gaussian, mean or deviation")
  message(FATAL_ERROR "clayform snapshot --mode wireframe: exit ${rc} (expected 2), stderr '${err}'")
endif()
foreach(command snapshot view)
  if(command STREQUAL "snapshot")
    set(args --png ${png})
  else()
    set(args --port 0)
  endif()
  execute_process(COMMAND ${CLAYFORM} ${command} ${WORK} ${args}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc TIMEOUT 30)
  if(NOT rc EQUAL 5 OR NOT err MATCHES "view/manifest.json is missing")
    message(FATAL_ERROR "clayform ${command} on a folder without view data: exit ${rc} (expected 5), stderr '${err}'")
  endif()
endforeach()
if(NOT EXISTS ${png})
  message(FATAL_ERROR "a failed clayform snapshot removed the previous ${png}")
endif()
