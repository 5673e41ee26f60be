# ctest install_consumer: installs the build tree BUILD_DIR into WORK_DIR/prefix, checks what
# landed there (files, no project compile flags in the installed interface), then configures,
# builds and runs the consumer project SOURCE_DIR against it, and builds the C program again
# with pkg-config.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DFORTRAN=ON|OFF -P ...
cmake_minimum_required(VERSION 3.22)
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR FORTRAN)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer_test.cmake: -D${var}=... is missing")
  endif()
endforeach()

# Runs a command; fails the test with its output when it fails. Its output in `run_output`.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE out
                  TIMEOUT 240)
  if(NOT code EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "`${command}` failed (${code}):\n${out}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

foreach(file bin/splinegrid lib/libsplinegrid_c.so lib/libsplinegrid_core.a
             lib/libsplinegrid_client.a lib/libsplinegrid_proto.a
             include/splinegrid/splinegrid.h include/splinegrid/client/client.h
             include/splinegrid/core/bspline/tensor_spline.h
             include/splinegrid/splinegrid/v1/grid.pb.h
             include/splinegrid/splinegrid/v1/splinegrid_service.grpc.pb.h
             lib/cmake/splinegrid/splinegridConfig.cmake
             lib/cmake/splinegrid/splinegridConfigVersion.cmake
             lib/cmake/splinegrid/splinegridTargets.cmake
             lib/pkgconfig/splinegrid.pc lib/pkgconfig/splinegrid-c.pc
             share/splinegrid/proto/splinegrid/v1/grid.proto)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "not installed: ${file}")
  endif()
endforeach()
if(EXISTS ${BUILD_DIR}/splinegrid-cgns-decode AND NOT EXISTS ${prefix}/bin/splinegrid-cgns-decode)
  message(FATAL_ERROR "not installed beside bin/splinegrid: splinegrid-cgns-decode")
endif()
if(FORTRAN AND NOT EXISTS ${prefix}/include/splinegrid/fortran/splinegrid.mod)
  message(FATAL_ERROR "not installed: include/splinegrid/fortran/splinegrid.mod")
endif()
# The installed interface carries no flag of the project's own (warnings, -march=native).
file(GLOB exported ${prefix}/lib/cmake/splinegrid/*.cmake ${prefix}/lib/pkgconfig/*.pc)
foreach(file ${exported})
  file(READ ${file} text)
  if(text MATCHES "-march|-Wall|-Wextra|-fno-math-errno|splinegrid_options")
    message(FATAL_ERROR "${file} carries a project compile flag: ${CMAKE_MATCH_0}")
  endif()
endforeach()

run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DCONSUMER_FORTRAN=${FORTRAN})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
file(READ ${WORK_DIR}/build/compile_commands.json commands)
if(commands MATCHES "-march=native|-Wextra")
  message(FATAL_ERROR "a project flag reached the consumer's compile lines: ${CMAKE_MATCH_0}")
endif()

# A port nothing listens on (1 is privileged and unused on a test machine).
set(nowhere 127.0.0.1:1)
file(READ ${prefix}/lib/cmake/splinegrid/splinegridConfigVersion.cmake version_file)
string(REGEX MATCH "PACKAGE_VERSION \"([0-9.]+)\"" _ "${version_file}")
set(version ${CMAKE_MATCH_1})
run(${WORK_DIR}/build/fit_curve)
message(STATUS "${run_output}")
run(${WORK_DIR}/build/client_call ${nowhere})
message(STATUS "${run_output}")
run(${WORK_DIR}/build/c_call ${nowhere} ${version})
message(STATUS "${run_output}")
if(FORTRAN)
  run(${WORK_DIR}/build/fortran_call ${nowhere})
  message(STATUS "${run_output}")
endif()

# pkg-config: the C++ flags name the headers and the static libraries (the kernel's program
# builds with them); the C program builds and runs with the C API's flags alone.
set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
run(pkg-config --cflags --libs splinegrid)
if(NOT run_output MATCHES "-I[^ ]*/include/splinegrid" OR NOT run_output MATCHES "-lsplinegrid_client"
   OR run_output MATCHES "march")
  message(FATAL_ERROR "pkg-config splinegrid: ${run_output}")
endif()
string(STRIP "${run_output}" cxx_flags)
separate_arguments(cxx_flags UNIX_COMMAND "${cxx_flags}")
run(c++ -std=c++20 ${SOURCE_DIR}/fit_curve.cc ${cxx_flags} -o ${WORK_DIR}/fit_curve_pkgconfig)
run(${WORK_DIR}/fit_curve_pkgconfig)
message(STATUS "pkg-config build: ${run_output}")
run(pkg-config --cflags --libs splinegrid-c)
string(STRIP "${run_output}" c_flags)
separate_arguments(c_flags UNIX_COMMAND "${c_flags}")
run(cc ${SOURCE_DIR}/c_call.c ${c_flags} -o ${WORK_DIR}/c_call_pkgconfig)
set(ENV{LD_LIBRARY_PATH} ${prefix}/lib)
run(${WORK_DIR}/c_call_pkgconfig ${nowhere} ${version})
message(STATUS "pkg-config build: ${run_output}")
