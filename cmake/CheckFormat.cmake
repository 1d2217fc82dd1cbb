# Run with cmake -P: fails listing every C++ or OpenCL source clang-format would change.
file(GLOB_RECURSE sources ${SOURCE_DIR}/host/*.cpp ${SOURCE_DIR}/host/*.h ${SOURCE_DIR}/include/*.h
     ${SOURCE_DIR}/kernels/*.cl ${SOURCE_DIR}/kernels/*.h ${SOURCE_DIR}/tests/*.cpp ${SOURCE_DIR}/tests/*.h
     ${SOURCE_DIR}/bench/*.cpp ${SOURCE_DIR}/bench/*.h)
set(unformatted "")
foreach(f ${sources})
  execute_process(COMMAND ${CLANG_FORMAT} --dry-run --Werror ${f} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 0)
    list(APPEND unformatted ${f})
  endif()
endforeach()
if(unformatted)
  string(REPLACE ";" "\n  " listing "${unformatted}")
  message(FATAL_ERROR "not clang-formatted (run clang-format -i):\n  ${listing}")
endif()
