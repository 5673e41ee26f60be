# `cmake --install build --prefix P`: the `splinegrid` tool (which also serves), the libraries,
# their headers under P/include/splinegrid with the include paths of the source tree
# ("core/grid/structured_grid.h", "client/client.h", generated "splinegrid/v1/grid.pb.h", the
# C API's "splinegrid.h"), the CMake package (find_package(splinegrid CONFIG): splinegrid::core,
# ::client, ::proto, ::c and ::fortran) and pkg-config files (splinegrid, splinegrid-c,
# splinegrid-fortran). Installed interfaces carry no compile flags of this project: its
# warnings and -march=native stay in splinegrid_options, which is linked as BUILD_INTERFACE only.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SPLINEGRID_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/splinegrid)
set(SPLINEGRID_HEADER_DIR ${CMAKE_INSTALL_INCLUDEDIR}/splinegrid)

set_target_properties(splinegrid_core PROPERTIES EXPORT_NAME core)
set_target_properties(splinegrid_proto PROPERTIES EXPORT_NAME proto)
set_target_properties(splinegrid_client PROPERTIES EXPORT_NAME client)
set(SPLINEGRID_EXPORTED splinegrid_core splinegrid_proto splinegrid_client splinegrid_c)
if(TARGET splinegrid_fortran)
  list(APPEND SPLINEGRID_EXPORTED splinegrid_fortran)
endif()

install(TARGETS ${SPLINEGRID_EXPORTED} EXPORT splinegridTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  PUBLIC_HEADER DESTINATION ${SPLINEGRID_HEADER_DIR})
install(TARGETS splinegrid RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# `splinegrid serve` runs the CGNS decoder (io/cgns) as a child process found beside itself.
if(TARGET splinegrid-cgns-decode)
  install(TARGETS splinegrid-cgns-decode RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# Headers: the kernel's, the C++ client's, the generated ones, and the .proto files for other
# languages' stubs.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/core/ DESTINATION ${SPLINEGRID_HEADER_DIR}/core
  FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_SOURCE_DIR}/client/client.h ${PROJECT_SOURCE_DIR}/client/retry.h
  DESTINATION ${SPLINEGRID_HEADER_DIR}/client)
install(DIRECTORY ${PROJECT_BINARY_DIR}/proto/gen/ DESTINATION ${SPLINEGRID_HEADER_DIR}
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/proto/splinegrid
  DESTINATION ${CMAKE_INSTALL_DATADIR}/splinegrid/proto FILES_MATCHING PATTERN "*.proto")
if(TARGET splinegrid_fortran)
  # The .mod is compiler-specific (gfortran's here); the module's source comes along for others.
  install(FILES ${PROJECT_BINARY_DIR}/capi/fortran_modules/splinegrid.mod
                ${PROJECT_SOURCE_DIR}/capi/fortran/splinegrid.f90
          DESTINATION ${SPLINEGRID_HEADER_DIR}/fortran)
endif()

install(EXPORT splinegridTargets NAMESPACE splinegrid:: DESTINATION ${SPLINEGRID_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/splinegridConfig.cmake.in
  ${PROJECT_BINARY_DIR}/splinegridConfig.cmake INSTALL_DESTINATION ${SPLINEGRID_CMAKE_DIR})
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/splinegridConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/splinegridConfig.cmake
              ${PROJECT_BINARY_DIR}/splinegridConfigVersion.cmake
        DESTINATION ${SPLINEGRID_CMAKE_DIR})

# pkg-config files, relocatable (${pcfiledir}), so that any --prefix works: the prefix is the
# pkgconfig directory's ancestor (../.. for lib/pkgconfig, ../../.. for lib/<multiarch>/pkgconfig).
file(RELATIVE_PATH SPLINEGRID_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" SPLINEGRID_PC_TO_PREFIX "${SPLINEGRID_PC_TO_PREFIX}")
set(SPLINEGRID_PC_FILES splinegrid splinegrid-c)
if(TARGET splinegrid_fortran)
  list(APPEND SPLINEGRID_PC_FILES splinegrid-fortran)
endif()
foreach(pc ${SPLINEGRID_PC_FILES})
  configure_file(${PROJECT_SOURCE_DIR}/cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/${pc}.pc
    @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/${pc}.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
