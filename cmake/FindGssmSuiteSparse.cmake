# Finds the SuiteSparse libraries gssm uses (CHOLMOD, CCOLAMD and their
# dependencies). Debian's SuiteSparse 5.12 ships no CMake config, so the
# libraries are located with find_library. Defines gssm::suitesparse.
include(FindPackageHandleStandardArgs)
find_path(GSSM_SUITESPARSE_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
set(_gssm_ss_libs cholmod ccolamd camd colamd amd suitesparseconfig)
set(GSSM_SUITESPARSE_LIBRARIES)
set(_gssm_ss_vars)
foreach(_lib IN LISTS _gssm_ss_libs)
  string(TOUPPER ${_lib} _up)
  find_library(GSSM_SUITESPARSE_${_up}_LIBRARY NAMES ${_lib})
  list(APPEND GSSM_SUITESPARSE_LIBRARIES ${GSSM_SUITESPARSE_${_up}_LIBRARY})
  list(APPEND _gssm_ss_vars GSSM_SUITESPARSE_${_up}_LIBRARY)
endforeach()
find_package_handle_standard_args(GssmSuiteSparse
  REQUIRED_VARS GSSM_SUITESPARSE_INCLUDE_DIR ${_gssm_ss_vars})
if(GssmSuiteSparse_FOUND AND NOT TARGET gssm::suitesparse)
  add_library(gssm::suitesparse INTERFACE IMPORTED)
  set_target_properties(gssm::suitesparse PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${GSSM_SUITESPARSE_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${GSSM_SUITESPARSE_LIBRARIES}")
endif()
