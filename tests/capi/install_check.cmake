# Installs the C API component into a scratch prefix and checks that a
# consumer can build and run the example through find_package(sogmm) and
# through pkg-config. Run with cmake -P (see CMakeLists.txt for variables).
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX} --component sogmm_capi)

# What was installed.
file(GLOB_RECURSE installed RELATIVE ${PREFIX} ${PREFIX}/*)
message(STATUS "installed: ${installed}")
foreach(expected include/sogmm/sogmm.h)
  if(NOT EXISTS ${PREFIX}/${expected})
    message(FATAL_ERROR "missing ${expected}")
  endif()
endforeach()
file(GLOB_RECURSE configs ${PREFIX}/*/sogmmConfig.cmake)
file(GLOB_RECURSE pcs ${PREFIX}/*/sogmm.pc)
file(GLOB_RECURSE libs ${PREFIX}/*/libsogmm.so)
if(NOT configs OR NOT pcs OR NOT libs)
  message(FATAL_ERROR "missing config (${configs}), pc (${pcs}) or library (${libs})")
endif()
# Only the C API: no C++ headers, no static archive but libsogmm.a.
foreach(f ${installed})
  if(f MATCHES "\\.hpp$" OR (f MATCHES "\\.a$" AND NOT f MATCHES "(^|/)libsogmm\\.a$"))
    message(FATAL_ERROR "installed a private file: ${f}")
  endif()
endforeach()

set(san_flags "")
if(SANITIZE)
  set(san_flags "-fsanitize=address,undefined")
endif()

# 1) find_package(sogmm)
run(${CMAKE_COMMAND} -S ${CONSUMER} -B ${WORK}/cmake-build -G ${GENERATOR}
    -DCMAKE_PREFIX_PATH=${PREFIX} -DCMAKE_C_COMPILER=${C_COMPILER} -DEXAMPLE=${EXAMPLE}
    "-DCMAKE_C_FLAGS=${san_flags}" "-DCMAKE_EXE_LINKER_FLAGS=${san_flags}")
run(${CMAKE_COMMAND} --build ${WORK}/cmake-build)
run(${WORK}/cmake-build/consumer_example ${WORK})
message(STATUS "find_package consumer:\n${run_output}")

# 2) pkg-config
find_program(PKG_CONFIG pkg-config)
if(PKG_CONFIG)
  list(GET pcs 0 pc)
  get_filename_component(pcdir ${pc} DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} ${pcdir})
  run(${PKG_CONFIG} --cflags --libs sogmm)
  string(STRIP "${run_output}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  message(STATUS "pkg-config --cflags --libs sogmm: ${flags}")
  separate_arguments(san UNIX_COMMAND "${san_flags}")
  run(${C_COMPILER} -std=c99 -Wall -Wextra -pedantic -Werror ${san} ${EXAMPLE} ${flags} -lm
      -o ${WORK}/pc_example)
  # No LD_LIBRARY_PATH: sogmm.pc's rpath finds the library.
  run(${WORK}/pc_example ${WORK})
  message(STATUS "pkg-config consumer:\n${run_output}")
else()
  message(STATUS "pkg-config not found: pkg-config consumer skipped")
endif()
