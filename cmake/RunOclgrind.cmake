# Run with cmake -P: runs TEST_BINARY (with TEST_ARGS, a ;-list, if given) under Oclgrind (data
# races, uninitialised reads, API errors; out-of-bounds accesses are always checked) and fails on
# any report or test failure.
# Oclgrind 21.10's --uninitialized cannot run LLVM's freeze instruction, hence -cl-opt-disable.
set(ENV{OCLGRIND_BUILD_OPTIONS} "-cl-opt-disable")
set(ENV{RTPG_CACHE_DIR} "${WORK_DIR}/cache")
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
execute_process(COMMAND ${OCLGRIND} --data-races --uninitialized --check-api --log ${WORK_DIR}/oclgrind.log
                        ${TEST_BINARY} ${TEST_ARGS} RESULT_VARIABLE rc)
file(READ ${WORK_DIR}/oclgrind.log reports)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TEST_BINARY} failed under Oclgrind (exit ${rc})\n${reports}")
endif()
if(NOT reports STREQUAL "")
  message(FATAL_ERROR "Oclgrind reported problems:\n${reports}")
endif()
