# pdcg_add_module(<name> [PUBLIC <targets>...] [PRIVATE <targets>...])
#
# Creates the library target pdcg_<name> (alias pdcg::<name>, exported as
# pdcg::<name>) from every src/<name>/*.cpp, with include/ as its public
# include directory. The module graph (who links whom) is documented once, in
# docs/architecture.md, and checked against the targets by ctest docs.module_graph.
# Sources are globbed so that adding a file to a module needs no edit here.
set(PDCG_MODULES "" CACHE INTERNAL "pdcg module targets")

function(pdcg_add_module name)
  cmake_parse_arguments(ARG "" "" "PUBLIC;PRIVATE" ${ARGN})
  file(GLOB _sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${name}/*.cpp)
  if(NOT _sources)
    message(FATAL_ERROR "pdcg_add_module(${name}): no sources in src/${name}/")
  endif()
  set(_target pdcg_${name})
  add_library(${_target} ${_sources})
  add_library(pdcg::${name} ALIAS ${_target})
  set_target_properties(${_target} PROPERTIES
    EXPORT_NAME ${name}
    OUTPUT_NAME pdcg_${name}
    VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  target_compile_features(${_target} PUBLIC cxx_std_20)
  target_include_directories(${_target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_options(${_target} PRIVATE -Wall -Wextra -Wpedantic)
  if(ARG_PUBLIC)
    target_link_libraries(${_target} PUBLIC ${ARG_PUBLIC})
  endif()
  if(ARG_PRIVATE)
    target_link_libraries(${_target} PRIVATE ${ARG_PRIVATE})
  endif()
  install(TARGETS ${_target} EXPORT pdcgTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  set(PDCG_MODULES ${PDCG_MODULES} ${_target} CACHE INTERNAL "pdcg module targets")
endfunction()

# pdcg_write_module_graph(<file>): writes the link properties of every module
# target, the umbrella pdcg::pdcg and the pdcg executable to <file>, one line per
# target: "target<TAB>kind<TAB>LINK_LIBRARIES<TAB>INTERFACE_LINK_LIBRARIES" (lists
# ';'-separated, unevaluated), plus "option<TAB>PDCG_ENABLE_LAMMPS<TAB>ON|OFF" and the same for
# PDCG_HAVE_PETSC (pdcg::parallel built).
# Called deferred at the end of the top-level directory (src/CMakeLists.txt), so
# every target_link_libraries call is included. Read by
# tests/docs/check_module_graph.py.
function(pdcg_write_module_graph file)
  set(_out "")
  foreach(_t IN LISTS PDCG_MODULES ITEMS pdcg_pdcg pdcg)
    if(NOT TARGET ${_t})
      continue()
    endif()
    get_target_property(_type ${_t} TYPE)
    set(_link "")
    if(NOT _type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(_link ${_t} LINK_LIBRARIES)
    endif()
    get_target_property(_iface ${_t} INTERFACE_LINK_LIBRARIES)
    foreach(_v _link _iface)
      if(NOT ${_v})
        set(${_v} "")
      endif()
    endforeach()
    string(APPEND _out "${_t}\t${_type}\t${_link}\t${_iface}\n")
  endforeach()
  if(PDCG_ENABLE_LAMMPS)
    string(APPEND _out "option\tPDCG_ENABLE_LAMMPS\tON\n")
  else()
    string(APPEND _out "option\tPDCG_ENABLE_LAMMPS\tOFF\n")
  endif()
  if(PDCG_HAVE_PETSC)
    string(APPEND _out "option\tPDCG_HAVE_PETSC\tON\n")
  else()
    string(APPEND _out "option\tPDCG_HAVE_PETSC\tOFF\n")
  endif()
  file(WRITE ${file} "${_out}")
endfunction()
