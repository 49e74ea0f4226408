# CTest fixture: installs the build tree into a fresh prefix and builds tests/consumer against it with find_package(tippe).
# -D BINARY_DIR=, PREFIX=, CONSUMER_SOURCE=, CONSUMER_BUILD=, CXX_COMPILER=, LAUNCHER= and SANITIZE= (may be empty)
file(REMOVE_RECURSE ${PREFIX} ${CONSUMER_BUILD})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${PREFIX} OUTPUT_QUIET
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BINARY_DIR} --prefix ${PREFIX} failed (${rc})")
endif()
foreach(f include/tippe/tippe.h include/tippe/analytic/scene.h include/tippe/engines/core/simulator.h
          lib/cmake/tippe/tippeConfig.cmake lib/cmake/tippe/tippeConfigVersion.cmake lib/pkgconfig/tippe.pc)
  if(NOT EXISTS ${PREFIX}/${f})
    message(FATAL_ERROR "the installed tree has no ${f}")
  endif()
endforeach()
set(args -S ${CONSUMER_SOURCE} -B ${CONSUMER_BUILD} -DCMAKE_PREFIX_PATH=${PREFIX} -DCMAKE_BUILD_TYPE=Release
         -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
if(LAUNCHER)
  list(APPEND args -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
if(SANITIZE)
  # The installed libraries of a sanitizer build call the sanitizers' runtime, which only the link
  # of an executable brings in.
  list(APPEND args "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} ${args} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer project failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${CONSUMER_BUILD} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer project failed (${rc})")
endif()
