# Runs CMD (a ;-list) and fails unless it exits with code 2 (bad input) and prints an error.
string(REPLACE "|" ";" CMD "${CMD}")
execute_process(COMMAND ${CMD} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "expected exit code 2, got '${rc}'\nstderr: ${err}")
endif()
if(NOT err MATCHES "omnivert: error: ")
  message(FATAL_ERROR "expected an error message on stderr, got: ${err}")
endif()
