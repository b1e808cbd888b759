# clayform_library(<target>): what every Clayform shared library shares (issue #19).
#
# - VERSION and SOVERSION from project(VERSION), here and nowhere else. While the major version is
#   0 the ABI may break at every minor release, so SOVERSION is 0.<minor> (libclay_surface.so.0.1:
#   a program built against 0.1 never loads a 0.2 library); from 1.0 on it is the major version.
#   ClayformConfigVersion.cmake's SameMinorVersion says the same to find_package.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(CLAYFORM_SOVERSION 0.${PROJECT_VERSION_MINOR})
else()
  set(CLAYFORM_SOVERSION ${PROJECT_VERSION_MAJOR})
endif()

function(clayform_library target)
  set_target_properties(${target} PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${CLAYFORM_SOVERSION})
endfunction()
