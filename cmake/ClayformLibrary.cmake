# clayform_library(<target> <MACRO> <header>): what every Clayform shared library shares (issue #19).
#
# - Its package name: clay_<name> is Clayform::<name>, as an ALIAS in this build and as the
#   exported name (EXPORT_NAME) in ClayformTargets.cmake, so an embedder writes the same
#   target_link_libraries(app Clayform::deform) against a build tree (add_subdirectory) or an
#   installed package (find_package).
# - Public headers: the calling folder's include/, from the source tree while building and from
#   the install prefix once installed.
# - Hidden symbol visibility: only what a public header marks with <MACRO> (CLAY_SURFACE_API, ...)
#   is exported; internal functions (namespace detail, src/*.hpp) and inline functions are not.
#   An embedder links against the API, not against whatever happened to have external linkage.
# - <header> (e.g. clay/surface/export.hpp) defines <MACRO>; GenerateExportHeader writes it under
#   the calling folder's build tree, include/<header>, which is on the target's include path and is
#   installed with the other headers (top CMakeLists.txt).
# - VERSION and SOVERSION from project(VERSION), here and nowhere else. While the major version is
#   0 the ABI may break at every minor release, so SOVERSION is 0.<minor> (libclay_surface.so.0.1:
#   a program built against 0.1 never loads a 0.2 library); from 1.0 on it is the major version.
#   ClayformConfigVersion.cmake's SameMinorVersion says the same to find_package.
include(GenerateExportHeader)

if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(CLAYFORM_SOVERSION 0.${PROJECT_VERSION_MINOR})
else()
  set(CLAYFORM_SOVERSION ${PROJECT_VERSION_MAJOR})
endif()

function(clayform_library target macro header)
  string(REGEX REPLACE "^clay_" "" name ${target})
  add_library(Clayform::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name}
    VERSION ${PROJECT_VERSION} SOVERSION ${CLAYFORM_SOVERSION}
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  string(REGEX REPLACE "_API$" "" base ${macro})
  generate_export_header(${target} BASE_NAME ${base} EXPORT_MACRO_NAME ${macro}
    EXPORT_FILE_NAME ${CMAKE_CURRENT_BINARY_DIR}/include/${header})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<BUILD_INTERFACE:${CMAKE_CURRENT_BINARY_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
endfunction()
