# install.cmake: what `make install` / `cmake --install` puts under the
# prefix, so that renderlab can be used as a dependency:
#   include/rl/*.h                      the public headers
#   lib/librenderlab.so*, librenderlab.a  shared (default) and static library
#   bin/rl                              the command-line tool
#   lib/pkgconfig/renderlab.pc          pkg-config (Requires/Libs.private: static linking)
#   lib/cmake/renderlab/                find_package(renderlab [COMPONENTS static])
# Everything is relocatable: the .pc finds its prefix from its own place,
# the CMake files from theirs, so DESTDIR and --prefix both work.
include(CMakePackageConfigHelpers)

set(RL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/renderlab)
set(RL_INSTALL_TARGETS renderlab)
if(RL_SHARED)
  list(APPEND RL_INSTALL_TARGETS renderlab_shared)
endif()

install(TARGETS ${RL_INSTALL_TARGETS} EXPORT renderlab-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS rl RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/rl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")
install(EXPORT renderlab-targets NAMESPACE renderlab:: DESTINATION ${RL_CMAKE_DIR})

configure_package_config_file(cmake/renderlab-config.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/renderlab-config.cmake INSTALL_DESTINATION ${RL_CMAKE_DIR})
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/renderlab-config-version.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/renderlab-config.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/renderlab-config-version.cmake
        DESTINATION ${RL_CMAKE_DIR})

# pkg-config: the prefix relative to the .pc file (${pcfiledir}).
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(RL_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH RL_PC_UP "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
  string(REGEX REPLACE "/$" "" RL_PC_UP "${RL_PC_UP}")
  set(RL_PC_PREFIX "\${pcfiledir}/${RL_PC_UP}")
endif()
set(RL_PC_LIBS_PRIVATE "-fopenmp -lstdc++ -lm")
if(RL_EMBREE)
  set(RL_PC_LIBS_PRIVATE "-lembree3 ${RL_PC_LIBS_PRIVATE}")
endif()
if(RL_GL)
  set(RL_PC_LIBS_PRIVATE "-lepoxy ${RL_PC_LIBS_PRIVATE}")
endif()
if(RL_MPI)
  # MPI has no one pkg-config name (Open MPI: ompi-c, MPICH: mpich): the
  # libraries CMake's FindMPI found, as paths.
  list(JOIN MPI_C_LIBRARIES " " RL_PC_MPI)
  set(RL_PC_LIBS_PRIVATE "${RL_PC_MPI} ${RL_PC_LIBS_PRIVATE}")
endif()
configure_file(cmake/renderlab.pc.in ${CMAKE_CURRENT_BINARY_DIR}/renderlab.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/renderlab.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

if(RL_NATIVE)
  install(CODE "message(WARNING \"renderlab was built with -march=native (RL_NATIVE): the installed \"
                \"binaries may not run on other machines; `make install` builds without it.\")")
endif()
