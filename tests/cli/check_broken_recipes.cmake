# Runs `clayform validate` and `clayform run` on every broken recipe of DIR (NN-name.json) and
# checks them against DIR/expected.txt (format in its header):
# - validate: exit 7 (recipe problems) and every expected substring printed (JSON path, or line
#   and column for syntax errors); a RUNTIME fixture must pass validate (exit 0) instead;
# - no output names a C++ options struct ("...Options::"): messages name recipe keys;
# - run --out WORK/NN: a clay error code (2..8: never 0, never 70 Internal, never a signal or
#   the 120 s timeout), 7 with the same substrings for recipes validate refuses, the expected
#   substrings for RUNTIME fixtures, and no partial files: WORK/NN absent or empty, nothing else
#   left in WORK.
# Every failure is collected and reported together (as one string: outputs may hold ';'). Usage:
#   cmake -DCLAYFORM=path/to/clayform -DDIR=tests/cli/recipes/broken -DWORK=scratch -P this.cmake
cmake_minimum_required(VERSION 3.22)  # IN_LIST, a script run with -P
foreach(var CLAYFORM DIR WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "give -D${var}=...")
  endif()
endforeach()

get_filename_component(DIR "${DIR}" ABSOLUTE)  # relative to the current directory
get_filename_component(WORK "${WORK}" ABSOLUTE)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

file(GLOB fixtures RELATIVE "${DIR}" "${DIR}/[0-9][0-9]-*.json")
list(SORT fixtures)
list(LENGTH fixtures fixture_count)
if(fixture_count LESS 20)
  message(FATAL_ERROR "expected 20 broken recipes NN-name.json in ${DIR}, found ${fixture_count}")
endif()

# Adds a failure to `failures` (blank-line separated) and counts it.
function(fail message)
  string(APPEND failures "${message}\n\n")
  math(EXPR failure_count "${failure_count} + 1")
  set(failures "${failures}" PARENT_SCOPE)
  set(failure_count ${failure_count} PARENT_SCOPE)
endfunction()

# expected.txt: "FIXTURE | SUBSTRING" per line; expect_<FIXTURE> collects the substrings and
# runtime_<FIXTURE> marks the fixtures that must pass validate and fail at run time.
set(failures "")
set(failure_count 0)
file(STRINGS "${DIR}/expected.txt" lines)
foreach(line IN LISTS lines)
  if(line STREQUAL "" OR line MATCHES "^#")
    continue()
  endif()
  string(FIND "${line}" " | " bar)
  if(bar LESS 1)
    fail("expected.txt: malformed line '${line}' (give FIXTURE | SUBSTRING)")
    continue()
  endif()
  string(SUBSTRING "${line}" 0 ${bar} fixture)
  math(EXPR start "${bar} + 3")
  string(SUBSTRING "${line}" ${start} -1 substring)
  if(NOT fixture IN_LIST fixtures)
    fail("expected.txt: no fixture ${fixture} in ${DIR}")
  elseif(substring STREQUAL "RUNTIME")
    set("runtime_${fixture}" TRUE)
  else()
    list(APPEND "expect_${fixture}" "${substring}")
  endif()
endforeach()

# Adds a failure for every substring of `fixture` missing from `text`.
function(check_substrings fixture command text)
  foreach(substring IN LISTS "expect_${fixture}")
    string(FIND "${text}" "${substring}" at)
    if(at EQUAL -1)
      fail("${fixture}: clayform ${command} did not print '${substring}':\n${text}")
    endif()
  endforeach()
  set(failures "${failures}" PARENT_SCOPE)
  set(failure_count ${failure_count} PARENT_SCOPE)
endfunction()

foreach(fixture IN LISTS fixtures)
  if(NOT DEFINED "expect_${fixture}")
    fail("${fixture}: no expectation in expected.txt")
    continue()
  endif()

  # validate
  execute_process(COMMAND "${CLAYFORM}" validate "${DIR}/${fixture}"
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc TIMEOUT 120)
  set(text "${out}${err}")
  if(runtime_${fixture})
    if(NOT rc STREQUAL "0")
      fail("${fixture}: must pass validate (a run-time failure), exit ${rc}:\n${text}")
    endif()
  else()
    if(NOT rc STREQUAL "7")
      fail("${fixture}: clayform validate exited '${rc}' (expected 7, recipe problems):\n${text}")
    endif()
    check_substrings("${fixture}" validate "${text}")
  endif()
  if(text MATCHES "Options::")
    fail("${fixture}: clayform validate names a C++ option instead of a recipe key:\n${text}")
  endif()

  # run: a clay error code, the expected message, no partial files
  string(SUBSTRING "${fixture}" 0 2 number)
  set(out_dir "${WORK}/${number}")
  file(GLOB before LIST_DIRECTORIES true "${WORK}/*")
  execute_process(COMMAND "${CLAYFORM}" run "${DIR}/${fixture}" --out "${out_dir}"
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc TIMEOUT 120)
  set(text "${out}${err}")
  if(runtime_${fixture})
    if(NOT rc MATCHES "^[2-8]$")
      fail("${fixture}: clayform run exited '${rc}' (expected a clay error code 2..8):\n${text}")
    endif()
  elseif(NOT rc STREQUAL "7")
    fail("${fixture}: clayform run exited '${rc}' (expected 7, recipe problems):\n${text}")
  endif()
  check_substrings("${fixture}" run "${text}")
  if(text MATCHES "Options::")
    fail("${fixture}: clayform run names a C++ option instead of a recipe key:\n${text}")
  endif()
  if(EXISTS "${out_dir}")
    file(GLOB_RECURSE written LIST_DIRECTORIES true "${out_dir}/*")
    if(written)
      fail("${fixture}: a failed run left files in ${out_dir}: ${written}")
    endif()
  endif()
  file(GLOB after LIST_DIRECTORIES true "${WORK}/*")
  list(REMOVE_ITEM after ${before} "${out_dir}")
  if(after)
    fail("${fixture}: a failed run left ${after} next to ${out_dir}")
  endif()
endforeach()

if(failure_count GREATER 0)
  message(NOTICE "${failures}")  # verbatim: FATAL_ERROR would re-wrap the outputs
  message(FATAL_ERROR "${failure_count} failure(s) over ${fixture_count} broken recipes (above)")
endif()
message(STATUS "${fixture_count} broken recipes: every problem reported, no run wrote a file")
