# SPDX-License-Identifier: MIT
# cmake -DCC=<compiler> -DSOURCE=<weights_compiled.c> -DINCLUDE=<firmware/include> -DCASES=<weights_cases dir>
#       -P check_weights_cases_build.cmake
# The firmware build against every case of tests/data/weights_cases/cases.tsv, with the flags of the
# firmware: a case marked 'build' must fail to compile, one marked 'build-named' too with a diagnostic that
# names the table's text (the field the firmware's own checks in weights_compiled.c refuse), every other
# one must compile. Together with the parsers' test of the same table, this shows the parsers refuse
# everything the build refuses.
cmake_minimum_required(VERSION 3.25)
file(STRINGS "${CASES}/cases.tsv" lines)
set(bad "")
foreach(line IN LISTS lines)
  if(line MATCHES "^#")
    continue()
  endif()
  string(REPLACE "\t" ";" cols "${line}")
  list(GET cols 0 file)
  list(GET cols 2 field)
  list(GET cols 3 firmware)
  execute_process(
    COMMAND "${CC}" -std=c99 -Wall -Wextra -Werror -Wconversion -fsyntax-only "-I${INCLUDE}"
            "-DPOUR_WEIGHTS_HEADER=\"${CASES}/${file}\"" "${SOURCE}"
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  # The field must appear in a diagnostic line, not only in an echoed source line.
  string(REGEX MATCHALL "[^\n]*(error|note)[^\n]*" diagnostics "${err}")
  string(JOIN "\n" diagnostics ${diagnostics})
  string(FIND "${diagnostics}" "${field}" at)
  if(firmware MATCHES "^build" AND rc EQUAL 0)
    list(APPEND bad "${file} compiled, but the table says the build refuses it")
  elseif(firmware STREQUAL "build-named" AND at EQUAL -1)
    list(APPEND bad "${file} failed to compile, but no diagnostic names ${field}:\n${err}")
  elseif(NOT firmware MATCHES "^build" AND NOT rc EQUAL 0)
    list(APPEND bad "${file} failed to compile, but the table says the build accepts it")
  else()
    message(STATUS "${file}: firmware build as listed (${firmware})")
  endif()
endforeach()
if(bad)
  string(JOIN "\n" bad ${bad})
  message(FATAL_ERROR "${bad}")
endif()
