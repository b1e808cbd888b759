# Checks that the C++ sources under SOURCE_DIR are formatted as .clang-format says, so the style is
# kept, not re-applied in one large commit now and then. Usage:
#   cmake -DSOURCE_DIR=<tree> [-DSTYLE_FILE=<.clang-format>] -P check_format.cmake
# Each misformatted file is named with clang-format's first complaint about it. The house fixture
# tests/house/fixtures/format/ holds one such file (the check must catch it), so the tree-wide run
# leaves that folder out. Fix a file with: clang-format-14 -i <file>.
find_program(CLANG_FORMAT NAMES clang-format-14 clang-format)
if(NOT CLANG_FORMAT)
  message(FATAL_ERROR "clang-format-14 not found: install the clang-format-14 package "
                      "(scripts/packages.txt; scripts/test.sh installs it)")
endif()
if(NOT STYLE_FILE)
  set(STYLE_FILE ${SOURCE_DIR}/.clang-format)
endif()
file(GLOB_RECURSE sources RELATIVE ${SOURCE_DIR}
  ${SOURCE_DIR}/*.cpp ${SOURCE_DIR}/*.hpp ${SOURCE_DIR}/*.h)
list(FILTER sources EXCLUDE REGEX "^(build[^/]*|viewer|\\.git)/|/node_modules/")
if(NOT SOURCE_DIR MATCHES "fixtures/format$")
  list(FILTER sources EXCLUDE REGEX "^tests/house/fixtures/format/")
endif()
list(LENGTH sources count)
if(count EQUAL 0)
  message(FATAL_ERROR "no C++ sources under ${SOURCE_DIR}")
endif()
# One clang-format run per hundred files (one per file took 48 s of a loaded CI machine, mostly in
# starting processes; all at once takes 2.5 s); each file is named with its first complaint.
set(bad "")
set(chunk "")
list(APPEND sources "")  # an empty last entry flushes the last chunk
foreach(file IN LISTS sources)
  if(file)
    list(APPEND chunk ${file})
  endif()
  list(LENGTH chunk n)
  if(n EQUAL 0 OR (file AND n LESS 100))
    continue()
  endif()
  execute_process(COMMAND ${CLANG_FORMAT} --style=file:${STYLE_FILE} --dry-run --Werror ${chunk}
    WORKING_DIRECTORY ${SOURCE_DIR} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT rc EQUAL 0)
    foreach(each IN LISTS chunk)
      string(REGEX REPLACE "([][+.*()^$?])" "\\\\\\1" quoted "${each}")
      string(REGEX MATCH "(^|\n)${quoted}:[^\n]*" first "${err}")
      string(STRIP "${first}" first)
      if(first)
        string(APPEND bad "\n  ${each}: ${first}")
      endif()
    endforeach()
    if(NOT bad)
      message(FATAL_ERROR "clang-format failed (exit ${rc}) without naming a file:\n${err}")
    endif()
  endif()
  set(chunk "")
endforeach()
if(bad)
  message(FATAL_ERROR "not formatted as .clang-format says (run clang-format-14 -i on each):${bad}")
endif()
message(STATUS "${count} C++ files formatted as ${STYLE_FILE} says")
