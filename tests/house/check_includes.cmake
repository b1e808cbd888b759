# House rules (STYLE.md 11, DESIGN.md's module graph):
# - OpenCASCADE headers only in surface/src/occt/ (an include counts as OCCT when the file exists
#   in OCCT's include folder), Ceres headers only in .cpp files;
# - a module includes only the clay headers of the modules it may use:
#     surface (the core: clay/surface*, clay/error.hpp, summary.hpp, tolerance.hpp, version.hpp)
#       <- sketch <- constraints;  surface <- brep <- deform;  the OCCT library (surface/src/occt/
#       and the exchange pre-check, Clayform::occt) uses surface and brep; cli (recipe, render,
#       servers) uses all; python (the pybind11 module) uses all.
#   The umbrella clay/clayform.hpp is exempt (it is the whole API by design).
# - clay/internal/ (the shared helpers, never installed) only from sources, never from a public
#   header under include/.
# -DSOURCE_DIR=<tree to scan> -DOCCT_INCLUDE_DIR=<OCCT headers>
cmake_minimum_required(VERSION 3.22)  # IN_LIST in a script run with -P
set(violations "")
set(may_use_surface surface)
set(may_use_sketch surface sketch)
set(may_use_constraints surface sketch constraints)
set(may_use_brep surface brep)
set(may_use_deform surface brep deform)
set(may_use_occt surface brep)
set(may_use_cli surface brep sketch constraints deform cli)
set(may_use_python surface brep sketch constraints deform cli)
# The module a clay header belongs to, or "" for a header outside the graph.
function(module_of header out)
  if(header MATCHES "^clay/(surface(/|\\.hpp$)|error\\.hpp$|summary\\.hpp$|tolerance\\.hpp$|version\\.hpp$|parallel\\.hpp$)")
    set(${out} surface PARENT_SCOPE)
  elseif(header STREQUAL "clay/internal/deformation_json.hpp")
    set(${out} deform PARENT_SCOPE)  # the stack schema's reader, shared with the recipe
  elseif(header MATCHES "^clay/(brep|sketch|constraints|deform)(/|\\.hpp$)")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  elseif(header MATCHES "^clay/(recipe|render|serve|view)(/|\\.hpp$)")
    set(${out} cli PARENT_SCOPE)
  else()
    set(${out} "" PARENT_SCOPE)
  endif()
endfunction()
file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR}
  ${SOURCE_DIR}/*.hpp ${SOURCE_DIR}/*.h ${SOURCE_DIR}/*.cpp ${SOURCE_DIR}/*.cc ${SOURCE_DIR}/*.hxx)
list(FILTER files EXCLUDE REGEX "^(build|out|\\.git)/|/fixtures/")
foreach(f ${files})
  file(STRINGS ${SOURCE_DIR}/${f} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  foreach(line ${includes})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"].*" "\\1" header "${line}")
    if(header MATCHES "^ceres/" AND NOT f MATCHES "\\.(cpp|cc)$")
      list(APPEND violations "${f}: Ceres header <${header}> outside a .cpp file")
    endif()
    if(EXISTS ${OCCT_INCLUDE_DIR}/${header} AND NOT f MATCHES "^surface/src/occt/")
      list(APPEND violations "${f}: OpenCASCADE header <${header}> outside surface/src/occt/")
    endif()
    if(header MATCHES "^clay/internal/" AND f MATCHES "/include/clay/" AND NOT f MATCHES "^internal/")
      list(APPEND violations "${f}: public header includes the internal <${header}>, which is not installed")
    endif()
    set(from "")
    if(f MATCHES "^surface/src/occt/")
      set(from occt)  # the OCCT library's sources live beside the core's
    elseif(f MATCHES "^(surface|brep|sketch|constraints|deform|cli|python)/")
      set(from ${CMAKE_MATCH_1})
    endif()
    if(from AND NOT f MATCHES "/clay/clayform\\.hpp$")
      module_of("${header}" to)
      if(to AND NOT to IN_LIST may_use_${from})
        list(APPEND violations "${f}: <${header}> belongs to module ${to}, which ${from} may not use")
      endif()
    endif()
  endforeach()
endforeach()
list(LENGTH files scanned)
if(violations)
  list(JOIN violations "\n  " text)
  message(FATAL_ERROR "include rules broken (${scanned} files scanned):\n  ${text}")
endif()
message(STATUS "include rules hold in ${scanned} files")
