# pdnav_module(NAME DEPS dep...): one static library per core module, pdnav::NAME,
# built from core-cpp/src/NAME/*.cpp with public headers in core-cpp/include/pdnav/NAME/.
# The dependency rule of docs/architecture.md is enforced here: a module's sources and
# headers may include only pdnav/<m>/ headers of itself and of the modules in DEPS
# (transitively); anything else fails the configure step with the offending file.
set(PDNAV_CORE_DIR "${CMAKE_CURRENT_LIST_DIR}/..")

function(pdnav_module name)
  cmake_parse_arguments(M "" "" "DEPS;LIBS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS "${PDNAV_CORE_DIR}/src/${name}/*.cpp")
  file(GLOB hdrs CONFIGURE_DEPENDS "${PDNAV_CORE_DIR}/include/pdnav/${name}/*.h"
                                   "${PDNAV_CORE_DIR}/src/${name}/*.h")
  # allowed = self + DEPS + their allowed sets (transitive)
  set(allowed ${name})
  foreach(d IN LISTS M_DEPS)
    get_property(dallowed GLOBAL PROPERTY PDNAV_ALLOWED_${d})
    list(APPEND allowed ${d} ${dallowed})
  endforeach()
  list(REMOVE_DUPLICATES allowed)
  set_property(GLOBAL PROPERTY PDNAV_ALLOWED_${name} "${allowed}")
  foreach(f IN LISTS srcs hdrs)
    file(STRINGS "${f}" incs REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]pdnav/")
    foreach(inc IN LISTS incs)
      string(REGEX REPLACE ".*pdnav/([a-z_]+)/.*" "\\1" used "${inc}")
      if(NOT used IN_LIST allowed)
        message(FATAL_ERROR "dependency rule: ${f} (module ${name}) includes pdnav/${used}/, "
                            "but ${name} may use only: ${allowed}")
      endif()
    endforeach()
  endforeach()

  set(tgt pdnav_${name})
  if(srcs)
    add_library(${tgt} STATIC ${srcs})
    target_include_directories(${tgt} PUBLIC "${PDNAV_CORE_DIR}/include"
                                      PRIVATE "${PDNAV_CORE_DIR}/src")
    set(deps)
    foreach(d IN LISTS M_DEPS)
      list(APPEND deps pdnav::${d})
    endforeach()
    target_link_libraries(${tgt} PUBLIC ${deps} Eigen3::Eigen ${M_LIBS})
    target_compile_options(${tgt} PRIVATE
      $<$<CXX_COMPILER_ID:GNU,Clang,AppleClang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>)
  else()
    # module not written yet: headers only
    add_library(${tgt} INTERFACE)
    target_include_directories(${tgt} INTERFACE "${PDNAV_CORE_DIR}/include")
    foreach(d IN LISTS M_DEPS)
      target_link_libraries(${tgt} INTERFACE pdnav::${d})
    endforeach()
    target_link_libraries(${tgt} INTERFACE Eigen3::Eigen)
  endif()
  add_library(pdnav::${name} ALIAS ${tgt})
endfunction()
