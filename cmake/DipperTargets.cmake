# dipper_add_module(name SOURCES ... HEADERS ... PUBLIC_DEPS ... PRIVATE_DEPS ...)
# One static library per module, alias dipper::<name>, headers installed under include/dipper/<name>/ so
# that `#include "dem/world.h"` works in the source tree and after install alike.

set(DIPPER_WARNING_FLAGS -Wall -Wextra -Wpedantic -Wshadow)
if(DIPPER_WARNINGS_AS_ERRORS)
  list(APPEND DIPPER_WARNING_FLAGS -Werror)
endif()
# Under -fsanitize, GCC 12's -Wmaybe-uninitialized flags std::function's move inside libstdc++'s <regex>
# (instantiated by scenario/sweep.cpp), a false positive in library code. The warning stays on in the other builds.
set(DIPPER_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
    -Wno-maybe-uninitialized)

# Flags every dipper target (library, test, example, benchmark) compiles with.
function(dipper_target_defaults target)
  target_compile_options(${target} PRIVATE ${DIPPER_WARNING_FLAGS})
  if(DIPPER_SANITIZE)
    target_compile_options(${target} PRIVATE ${DIPPER_SANITIZER_FLAGS})
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

function(dipper_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;HEADERS;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(dipper_${name} STATIC ${ARG_SOURCES} ${ARG_HEADERS})
  add_library(dipper::${name} ALIAS dipper_${name})
  set_target_properties(dipper_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME dipper_${name})
  target_include_directories(dipper_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/dipper>)
  target_compile_features(dipper_${name} PUBLIC cxx_std_17)
  target_link_libraries(dipper_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  dipper_target_defaults(dipper_${name})
  if(DIPPER_SANITIZE)
    target_link_options(dipper_${name} INTERFACE -fsanitize=address,undefined)
  endif()
  install(TARGETS dipper_${name} EXPORT dipperTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  foreach(header ${ARG_HEADERS})
    get_filename_component(dir ${header} DIRECTORY)
    install(FILES ${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dipper/${dir})
  endforeach()
endfunction()
