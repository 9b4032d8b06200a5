# Sequential MUMPS 5.5 (Debian 12: libmumps-seq-dev + libmumps-headers-dev) ships no CMake config: find the
# double-precision C interface and its libraries by hand (docs/dependencies.md §2.4). The sequential build
# carries its own MPI stubs, so no MPI is needed.
if(NOT TARGET MUMPS::dmumps_seq)
  find_path(MUMPS_INCLUDE_DIR dmumps_c.h PATH_SUFFIXES mumps_seq)
  find_library(DMUMPS_SEQ_LIBRARY dmumps_seq)
  find_library(MUMPS_COMMON_SEQ_LIBRARY mumps_common_seq)
  if(NOT MUMPS_INCLUDE_DIR OR NOT DMUMPS_SEQ_LIBRARY OR NOT MUMPS_COMMON_SEQ_LIBRARY)
    message(FATAL_ERROR "sequential MUMPS not found (dmumps_c.h: ${MUMPS_INCLUDE_DIR}, libdmumps_seq: "
                        "${DMUMPS_SEQ_LIBRARY}, libmumps_common_seq: ${MUMPS_COMMON_SEQ_LIBRARY}): install "
                        "libmumps-seq-dev (scripts/install-deps.sh)")
  endif()
  add_library(MUMPS::dmumps_seq INTERFACE IMPORTED)
  target_include_directories(MUMPS::dmumps_seq INTERFACE ${MUMPS_INCLUDE_DIR})
  target_link_libraries(MUMPS::dmumps_seq INTERFACE ${DMUMPS_SEQ_LIBRARY} ${MUMPS_COMMON_SEQ_LIBRARY})
endif()
