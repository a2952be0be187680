# ctest fixture: record one simulated session afresh into OUT with the
# record-session TOOL (tests that share it copy it instead of recording it
# again in every test process).
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${TOOL}" sim --out "${OUT}" RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "record-session sim --out ${OUT} exited ${result}")
endif()
