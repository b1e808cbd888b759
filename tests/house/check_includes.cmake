# House rules (docs/design.md's module graph, issue #37): a module is a top-level folder, with no
# special cases.
# - Every file under folder M belongs to module M. A clay header belongs to the folder that holds
#   it: M/include/<header> (public, installed), M/include/<header>.in (a template configured into
#   the build tree), M/detail/<header> (a module's detail header: shared with the modules above,
#   never installed), or the folder whose include/ holds the header's directory (the generated
#   clay/<name>/export.hpp). The top-level include/ (the umbrella clay/clayform.hpp) is the
#   module "include". The helpers every module shares (clay/internal/) are the core's detail
#   headers (surface/detail/).
# - A module includes only headers of the modules it may use (below); an unknown clay header, or
#   a quoted include that climbs out of its folder (".."), is a violation too.
# - OpenCASCADE headers only under occt/ (an include counts as OCCT when the file exists in
#   OCCT's include folder); Ceres headers only in .cpp files.
# - A public header (M/include/...) never includes a detail or internal header: neither is
#   installed.
# Folders not in the graph (tests, bench, examples, build trees) may include anything.
# -DSOURCE_DIR=<tree to scan> -DOCCT_INCLUDE_DIR=<OCCT headers>
# [-DMODULES_DIR=<tree whose folders own the headers>; default SOURCE_DIR: fixtures scan a small
#  tree but resolve headers against the project's]
cmake_minimum_required(VERSION 3.22)  # IN_LIST in a script run with -P
if(NOT MODULES_DIR)
  set(MODULES_DIR ${SOURCE_DIR})
endif()
set(violations "")
set(may_use_surface surface)
set(may_use_brep surface brep)
set(may_use_occt surface brep occt)
set(may_use_sketch surface sketch)
set(may_use_constraints surface sketch constraints)
set(may_use_deform surface brep deform)
set(may_use_recipe surface brep occt sketch constraints deform recipe)
set(may_use_render surface brep render)
set(may_use_include surface brep occt sketch constraints deform recipe render include)
set(may_use_cli surface brep occt sketch constraints deform recipe render cli)
set(may_use_python surface brep occt sketch constraints deform recipe render include python)
# The modules bottom up: a module may use only itself and modules before it, so no arrow of the
# graph can run upward (checked below, so a careless edit of a list above cannot add one).
set(modules surface brep occt sketch constraints deform recipe render include cli python)
foreach(m ${modules})
  list(FIND modules ${m} at)
  foreach(used ${may_use_${m}})
    list(FIND modules ${used} used_at)
    if(used_at GREATER at)
      message(FATAL_ERROR "the graph itself lets ${m} use ${used}, which comes after it (upward)")
    endif()
  endforeach()
endforeach()
set(edges "")

# The module owning a clay header, and whether it is installed ("public") or not ("private");
# module "" when no folder holds it.
function(owner_of header out_module out_kind)
  set(${out_module} "" PARENT_SCOPE)
  set(${out_kind} "" PARENT_SCOPE)
  if(EXISTS ${MODULES_DIR}/include/${header})
    set(${out_module} include PARENT_SCOPE)
    set(${out_kind} public PARENT_SCOPE)
    return()
  endif()
  get_filename_component(dir ${header} DIRECTORY)
  get_filename_component(name ${header} NAME)
  foreach(m ${modules})
    if(EXISTS ${MODULES_DIR}/${m}/include/${header} OR EXISTS ${MODULES_DIR}/${m}/include/${header}.in)
      set(${out_module} ${m} PARENT_SCOPE)
      set(${out_kind} public PARENT_SCOPE)
      return()
    endif()
    if(EXISTS ${MODULES_DIR}/${m}/detail/${header})
      set(${out_module} ${m} PARENT_SCOPE)
      set(${out_kind} private PARENT_SCOPE)
      return()
    endif()
    if(name STREQUAL "export.hpp" AND NOT dir STREQUAL "clay" AND IS_DIRECTORY ${MODULES_DIR}/${m}/include/${dir})
      set(${out_module} ${m} PARENT_SCOPE)
      set(${out_kind} public PARENT_SCOPE)
      return()
    endif()
  endforeach()
endfunction()

file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR}
  ${SOURCE_DIR}/*.hpp ${SOURCE_DIR}/*.h ${SOURCE_DIR}/*.cpp ${SOURCE_DIR}/*.cc ${SOURCE_DIR}/*.hxx)
list(FILTER files EXCLUDE REGEX "^(build[^/]*|out|\\.git|node_modules)/|/fixtures/")
foreach(f ${files})
  string(REGEX MATCH "^[^/]+" top "${f}")
  set(from "")
  if(top IN_LIST modules)
    set(from ${top})
  endif()
  file(STRINGS ${SOURCE_DIR}/${f} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  foreach(line ${includes})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*([<\"])([^>\"]+)[>\"].*" "\\1;\\2" parsed "${line}")
    list(GET parsed 0 quote)
    list(GET parsed 1 header)
    if(header MATCHES "^ceres/" AND NOT f MATCHES "\\.(cpp|cc)$")
      list(APPEND violations "${f}: Ceres header <${header}> outside a .cpp file")
    endif()
    if(EXISTS ${OCCT_INCLUDE_DIR}/${header} AND NOT from STREQUAL "occt")
      list(APPEND violations "${f}: OpenCASCADE header <${header}> outside occt/")
    endif()
    if(NOT from)
      continue()
    endif()
    if(quote STREQUAL "\"")
      if(header MATCHES "(^|/)\\.\\./")
        list(APPEND violations "${f}: \"${header}\" climbs out of its folder; include another module's header as <clay/...>")
      endif()
      continue()
    endif()
    if(NOT header MATCHES "^clay/")
      continue()
    endif()
    owner_of("${header}" to kind)
    if(NOT to)
      list(APPEND violations "${f}: <${header}> is in no module's include/ or detail/ folder")
      continue()
    endif()
    if(NOT to STREQUAL from)
      list(APPEND edges "${from} -> ${to}")
    endif()
    if(NOT to IN_LIST may_use_${from})
      list(APPEND violations "${f}: <${header}> belongs to module ${to}, which ${from} may not use")
    endif()
    if(kind STREQUAL "private" AND f MATCHES "^[^/]+/include/")
      list(APPEND violations "${f}: public header includes <${header}>, which is not installed (detail or internal)")
    endif()
  endforeach()
endforeach()
list(LENGTH files scanned)
if(violations)
  list(JOIN violations "\n  " text)
  message(FATAL_ERROR "include rules broken (${scanned} files scanned):\n  ${text}")
endif()
list(REMOVE_DUPLICATES edges)
list(SORT edges)
list(JOIN edges "; " graph)
message(STATUS "include rules hold in ${scanned} files; the module graph read from them: ${graph}")
