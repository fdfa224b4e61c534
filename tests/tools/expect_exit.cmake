# Runs CMD (a |-list) and fails unless it exits with code CODE and its stderr matches REGEX.
string(REPLACE "|" ";" CMD "${CMD}")
execute_process(COMMAND ${CMD} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT rc EQUAL CODE)
  message(FATAL_ERROR "expected exit code ${CODE}, got '${rc}'\nstderr: ${err}")
endif()
if(NOT err MATCHES "${REGEX}")
  message(FATAL_ERROR "expected stderr to match '${REGEX}', got: ${err}")
endif()
