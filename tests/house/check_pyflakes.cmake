# Lints the Python sources under SOURCE_DIR with pyflakes (Debian's pyflakes3: unused or undefined
# names, redefinitions, f-strings without fields, ...), as check_format.cmake keeps the C++ style.
# Usage: cmake -DSOURCE_DIR=<tree> -DPYTHON=<interpreter> -P check_pyflakes.cmake
# The house fixture tests/house/fixtures/python/ holds a file with findings (the check must name
# them), so the tree-wide run leaves that folder out.
file(GLOB_RECURSE sources RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/*.py)
list(FILTER sources EXCLUDE REGEX "^(build[^/]*|\\.git)/|/node_modules/|__pycache__")
if(NOT SOURCE_DIR MATCHES "fixtures/python$")
  list(FILTER sources EXCLUDE REGEX "^tests/house/fixtures/")
endif()
list(LENGTH sources count)
if(count EQUAL 0)
  message(FATAL_ERROR "no Python sources under ${SOURCE_DIR}")
endif()
execute_process(COMMAND ${PYTHON} -m pyflakes ${sources} WORKING_DIRECTORY ${SOURCE_DIR}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(err MATCHES "No module named pyflakes")
  message(FATAL_ERROR "pyflakes not found: install the pyflakes3 package "
                      "(scripts/packages.txt; scripts/test.sh installs it)")
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pyflakes findings in the Python sources:\n${out}${err}")
endif()
message(STATUS "${count} Python files pass pyflakes")
