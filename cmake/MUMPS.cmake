# Sequential MUMPS 5.5 (Debian 12: libmumps-seq-dev + libmumps-headers-dev) ships no CMake config: find the
# double-precision C interface and its library by hand (docs/dependencies.md §2.4). The library is not linked:
# lib/linalg/linear_solver.cpp loads it with dlopen(RTLD_LOCAL), because its built-in MPI stubs export MPI_Init & co.
# and would shadow Open MPI in executables that use both. Its full path is compiled in.
if(NOT TARGET MUMPS::dmumps_seq)
  find_path(MUMPS_INCLUDE_DIR dmumps_c.h PATH_SUFFIXES mumps_seq)
  find_library(DMUMPS_SEQ_LIBRARY dmumps_seq)
  if(NOT MUMPS_INCLUDE_DIR OR NOT DMUMPS_SEQ_LIBRARY)
    message(FATAL_ERROR "sequential MUMPS not found (dmumps_c.h: ${MUMPS_INCLUDE_DIR}, libdmumps_seq: "
                        "${DMUMPS_SEQ_LIBRARY}): install libmumps-seq-dev (scripts/install-deps.sh)")
  endif()
  get_filename_component(DMUMPS_SEQ_RUNTIME "${DMUMPS_SEQ_LIBRARY}" REALPATH)  # the runtime package's file
  add_library(MUMPS::dmumps_seq INTERFACE IMPORTED)
  target_include_directories(MUMPS::dmumps_seq INTERFACE ${MUMPS_INCLUDE_DIR})
  target_compile_definitions(MUMPS::dmumps_seq INTERFACE SHELLDYN_DMUMPS_SEQ_LIBRARY="${DMUMPS_SEQ_RUNTIME}")
  target_link_libraries(MUMPS::dmumps_seq INTERFACE ${CMAKE_DL_LIBS})
endif()
