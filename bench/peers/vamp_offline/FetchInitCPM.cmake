# cellplan bench/peers: replaces VAMP's cmake/FetchInitCPM.cmake, which downloads CPM.cmake from
# GitHub (unreachable here). The CPMAddPackage below resolves VAMP's fetched dependencies
# locally instead (see build.sh):
#   gh:wjakob/nanobind      -> the nanobind Python package of the build environment
#   gh:kavrakilab/nigh      -> bench/peers/vamp_offline/nigh/src/nigh (a stand-in, see nigh_forward.hpp)
#   gh:orlp/pdqsort         -> Debian's pdqsort-dev (/usr/include/pdqsort.h)
#   gh:lemire/SIMDxorshift  -> not built: VAMP's `xorshift` sampler raises; its default
#                              `halton` sampler is unaffected
macro(CPMAddPackage spec)
  if("${spec}" MATCHES "nanobind")
    execute_process(
      COMMAND "${Python_EXECUTABLE}" -m nanobind --cmake_dir
      OUTPUT_VARIABLE _cellplan_nb_dir OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
    find_package(nanobind CONFIG REQUIRED PATHS "${_cellplan_nb_dir}" NO_DEFAULT_PATH)
  elseif("${spec}" MATCHES "nigh")
    set(nigh_SOURCE_DIR "${CMAKE_SOURCE_DIR}/cellplan_offline/nigh")
    set(nigh_ADDED YES)
  elseif("${spec}" MATCHES "pdqsort")
    if(NOT EXISTS "/usr/include/pdqsort.h")
      message(FATAL_ERROR "pdqsort.h missing: apt-get install pdqsort-dev")
    endif()
    file(COPY "/usr/include/pdqsort.h" DESTINATION "${CMAKE_BINARY_DIR}/cellplan_pdqsort")
    set(pdqsort_SOURCE_DIR "${CMAKE_BINARY_DIR}/cellplan_pdqsort")
    set(pdqsort_ADDED YES)
  else()
    message(STATUS "cellplan offline build: skipping ${spec}")
  endif()
endmacro()
