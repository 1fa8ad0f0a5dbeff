# Configures, builds and runs the add_subdirectory consumer. Any failure fails the test.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR} -DHEMILIGHT_SOURCE_DIR=${HEMILIGHT_SOURCE_DIR}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE})
run(${CMAKE_COMMAND} --build ${WORK_DIR} --target consumer_cpp consumer_c -j 2)
run(${WORK_DIR}/consumer_cpp)
run(${WORK_DIR}/consumer_c)
message(STATUS "subdirectory consumer: add_subdirectory works")
