# SPDX-License-Identifier: MIT
# cmake -DCC=<compiler> -DSOURCE=<weights_compiled.c> -DINCLUDE=<firmware/include> -DHEADER=<weights.h>
#       [-DFIELD=<name>] -P expect_compile_error.cmake
# With FIELD: passes only if compiling SOURCE against HEADER fails AND the compiler's message names
# FIELD. Without FIELD: passes only if it compiles (the control case: the check itself works).
foreach(var CC SOURCE INCLUDE HEADER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "expect_compile_error: -D${var}=... is required")
  endif()
endforeach()
execute_process(
  COMMAND "${CC}" -std=c99 -Wall -Wextra -Werror -Wconversion -fsyntax-only "-I${INCLUDE}"
          "-DPOUR_WEIGHTS_HEADER=\"${HEADER}\"" "${SOURCE}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT DEFINED FIELD)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "a good weights.h failed to compile:\n${err}")
  endif()
  message(STATUS "${HEADER} compiles")
  return()
endif()
if(rc EQUAL 0)
  message(FATAL_ERROR "${HEADER} compiled, but it is bad (${FIELD}): the build must refuse it")
endif()
# The field must appear in a diagnostic line, not only in an echoed source line.
string(REGEX MATCHALL "[^\n]*(error|note)[^\n]*" diagnostics "${err}")
string(JOIN "\n" diagnostics ${diagnostics})
string(FIND "${diagnostics}" "${FIELD}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${HEADER} failed to compile, but no diagnostic names ${FIELD}:\n${err}")
endif()
message(STATUS "${HEADER} refused, naming ${FIELD}")
