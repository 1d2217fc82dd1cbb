# The guiding library as another renderer takes it: install rtpg into a fresh prefix, build
# examples/minimal_guiding against it with find_package(rtpg), run it (it exits non-zero
# unless guiding lowers its error). Run by ctest as `install_example`:
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -P install_and_build_example.cmake
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/minimal_guiding
                        -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
                        -DCMAKE_BUILD_TYPE=Release
                        # A sanitized rtpg (RTPG_SANITIZE) needs its runtime in the example too.
                        -DCMAKE_CXX_FLAGS=${EXAMPLE_FLAGS} -DCMAKE_EXE_LINKER_FLAGS=${EXAMPLE_FLAGS}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the example against the install tree failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the example failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/build/minimal_guiding 32 64 RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "minimal_guiding exited with ${rc}")
endif()
