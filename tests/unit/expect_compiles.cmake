# SPDX-License-Identifier: MIT
# cmake -DCC=<compiler> -DSOURCE=<weights_compiled.c> -DINCLUDE=<firmware/include> -DHEADER=<weights.h>
#       -P expect_compiles.cmake
# Passes only if SOURCE compiles against HEADER with the firmware's flags: the control case for the bad
# headers of tests/data/weights_cases, which tests/sim/check_weights_cases_build.cmake expects refused.
foreach(var CC SOURCE INCLUDE HEADER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "expect_compiles: -D${var}=... is required")
  endif()
endforeach()
execute_process(
  COMMAND "${CC}" -std=c99 -Wall -Wextra -Werror -Wconversion -fsyntax-only "-I${INCLUDE}"
          "-DPOUR_WEIGHTS_HEADER=\"${HEADER}\"" "${SOURCE}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "a good weights.h failed to compile:\n${err}")
endif()
message(STATUS "${HEADER} compiles")
