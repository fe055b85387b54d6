# SPDX-License-Identifier: MIT
# cmake -DCHECKER=<check_no_float.cmake> -DREADELF=<readelf> -DFILE=<object> -DSYMBOL=<helper> -P expect_float_found.cmake
# Passes only if the checker fails on FILE and names SYMBOL in its message.
execute_process(COMMAND "${CMAKE_COMMAND}" "-DREADELF=${READELF}" "-DFILES=${FILE}" -P "${CHECKER}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "check_no_float accepted ${FILE}, which uses float:\n${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${SYMBOL}")
  message(FATAL_ERROR "check_no_float failed but did not name ${SYMBOL}:\n${out}${err}")
endif()
message(STATUS "check_no_float refused ${FILE} and named ${SYMBOL}")
