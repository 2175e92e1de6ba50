# FindSuiteSparse — Debian's libsuitesparse-dev 5.x ships no CMake config.
# Components: CHOLMOD, UMFPACK. Defines SuiteSparse::CHOLMOD, SuiteSparse::UMFPACK.
find_path(SuiteSparse_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(SuiteSparse_config_LIBRARY NAMES suitesparseconfig)
set(_ss_required SuiteSparse_INCLUDE_DIR SuiteSparse_config_LIBRARY)
foreach(comp IN LISTS SuiteSparse_FIND_COMPONENTS)
  string(TOLOWER ${comp} _lc)
  find_library(SuiteSparse_${comp}_LIBRARY NAMES ${_lc})
  if(SuiteSparse_${comp}_LIBRARY)
    set(SuiteSparse_${comp}_FOUND TRUE)
  endif()
  list(APPEND _ss_required SuiteSparse_${comp}_LIBRARY)
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparse REQUIRED_VARS ${_ss_required} HANDLE_COMPONENTS)
if(SuiteSparse_FOUND)
  foreach(comp IN LISTS SuiteSparse_FIND_COMPONENTS)
    if(NOT TARGET SuiteSparse::${comp})
      add_library(SuiteSparse::${comp} UNKNOWN IMPORTED)
      set_target_properties(SuiteSparse::${comp} PROPERTIES
        IMPORTED_LOCATION "${SuiteSparse_${comp}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}"
        INTERFACE_LINK_LIBRARIES "${SuiteSparse_config_LIBRARY}")
    endif()
  endforeach()
endif()
mark_as_advanced(SuiteSparse_INCLUDE_DIR SuiteSparse_config_LIBRARY)
