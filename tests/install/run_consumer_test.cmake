# Installs the built project into a scratch prefix, then configures, builds and runs a consumer
# project that only knows find_package(Clayform) and links Clayform::deform.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(f include/clay/surface/bspline_surface.hpp include/clay/deform.hpp include/clay/version.hpp
          include/clay/surface/export.hpp include/clay/occt/export.hpp
          include/clay/sketch/export.hpp include/clay/constraints/export.hpp
          include/clay/deform/export.hpp include/clay/recipe/export.hpp include/clay/render/export.hpp
          include/clay/occt.hpp include/clay/occt/surface_exchange.hpp include/clay/brep/mesh.hpp
          include/clay/clayform.hpp
          lib/cmake/Clayform/ClayformConfig.cmake lib/cmake/Clayform/ClayformConfigVersion.cmake
          bin/clayform)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "install is missing ${f}")
  endif()
endforeach()
# Never installed: the OCCT library's sources' headers (convert, session, the OCCT reference),
# the modules' detail headers, the shared internal helpers, the command's servers, templates.
file(GLOB_RECURSE leaked ${WORK_DIR}/prefix/include/*reference* ${WORK_DIR}/prefix/include/*convert*
     ${WORK_DIR}/prefix/include/*session* ${WORK_DIR}/prefix/include/*/detail/*
     ${WORK_DIR}/prefix/include/clay/internal/* ${WORK_DIR}/prefix/include/clay/serve.hpp
     ${WORK_DIR}/prefix/include/clay/studio.hpp ${WORK_DIR}/prefix/include/*.in)
if(leaked)
  message(FATAL_ERROR "internal headers were installed: ${leaked}")
endif()
# The consumer is compiled like the project: same compiler and, for a sanitized build (whose
# libraries call the sanitizer runtime), the same -fsanitize, which links that runtime in.
set(consumer_flags)
if(CXX_COMPILER)
  list(APPEND consumer_flags -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
if(SANITIZE)
  list(APPEND consumer_flags -DCMAKE_CXX_FLAGS=-fsanitize=${SANITIZE} -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE})
endif()
run(${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix ${consumer_flags})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer ${WORK_DIR}/consumer.step)
if(NOT last_output MATCHES "consumer ok")
  message(FATAL_ERROR "consumer printed: ${last_output}")
endif()
run(${WORK_DIR}/prefix/bin/clayform info ${WORK_DIR}/consumer.step)
message(STATUS "${last_output}")
# The Python package, when built: importable from the prefix alone (its RPATH reaches the
# installed libraries, not the build tree's), and it runs a recipe.
if(PYTHON AND PYTHON_INSTALL_DIR)
  set(site ${WORK_DIR}/prefix/${PYTHON_INSTALL_DIR})
  if(NOT EXISTS ${site}/clayform/__init__.py OR NOT EXISTS ${site}/clayform/py.typed)
    message(FATAL_ERROR "install is missing the Python package in ${site}")
  endif()
  # (No ";" in the code: CMake would split the argument there.)
  run(${CMAKE_COMMAND} -E env PYTHONPATH=${site} ${PYTHON} -c
      "import clayform as c\nassert c.__file__.startswith('${site}'), c.__file__\nprint('python', len(c.read_step('${WORK_DIR}/consumer.step')))")
  if(NOT last_output MATCHES "python [1-9]")
    message(FATAL_ERROR "the installed package printed: ${last_output}")
  endif()
  message(STATUS "installed Python package: ${last_output}")
endif()
