# FindFFTW3 — Debian's libfftw3-dev ships no CMake config (only pkg-config).
# Defines FFTW3::fftw3 (double precision) and FFTW3_FOUND.
find_path(FFTW3_INCLUDE_DIR fftw3.h)
find_library(FFTW3_LIBRARY NAMES fftw3)
find_library(FFTW3_OMP_LIBRARY NAMES fftw3_omp)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(FFTW3 REQUIRED_VARS FFTW3_LIBRARY FFTW3_INCLUDE_DIR)
if(FFTW3_FOUND AND NOT TARGET FFTW3::fftw3)
  add_library(FFTW3::fftw3 UNKNOWN IMPORTED)
  set_target_properties(FFTW3::fftw3 PROPERTIES
    IMPORTED_LOCATION "${FFTW3_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${FFTW3_INCLUDE_DIR}")
  if(FFTW3_OMP_LIBRARY)
    add_library(FFTW3::fftw3_omp UNKNOWN IMPORTED)
    set_target_properties(FFTW3::fftw3_omp PROPERTIES
      IMPORTED_LOCATION "${FFTW3_OMP_LIBRARY}"
      INTERFACE_LINK_LIBRARIES FFTW3::fftw3)
  endif()
endif()
mark_as_advanced(FFTW3_INCLUDE_DIR FFTW3_LIBRARY FFTW3_OMP_LIBRARY)
