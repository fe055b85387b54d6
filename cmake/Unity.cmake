# SPDX-License-Identifier: MIT
# Unity (ThrowTheSwitch) from the sources scripts/setup.sh placed in POUR_DEPS_DIR.
set(POUR_UNITY_DIR "${POUR_DEPS_DIR}/unity")
if(NOT EXISTS "${POUR_UNITY_DIR}/unity.c")
  message(FATAL_ERROR "Unity not found in ${POUR_UNITY_DIR}: run scripts/setup.sh first")
endif()
add_library(unity STATIC "${POUR_UNITY_DIR}/unity.c")
target_include_directories(unity SYSTEM PUBLIC "${POUR_UNITY_DIR}")
if(CMAKE_CROSSCOMPILING)
  # The firmware is fixed point: keep float support out of the on-target test runner too.
  target_compile_definitions(unity PUBLIC UNITY_EXCLUDE_FLOAT UNITY_EXCLUDE_DOUBLE)
else()
  target_compile_definitions(unity PUBLIC UNITY_INCLUDE_DOUBLE)
endif()

# pour_add_unity_test(name SOURCES src... [LIBS lib...] [LABELS label...]): one Unity executable linked with
# pour::core, registered for the host (labels unit and LABELS) or, in the cross build, run on the emulated
# Cortex-M4 under QEMU (label mcu). The same sources serve both.
function(pour_add_unity_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE unity pour::core ${ARG_LIBS})
  pour_warnings(${name})
  if(CMAKE_CROSSCOMPILING)
    pour_cm4_semihosted(${name})
    add_test(NAME mcu_${name} COMMAND ${name})
    set_tests_properties(mcu_${name} PROPERTIES LABELS mcu TIMEOUT 120)
  else()
    add_test(NAME ${name} COMMAND ${name})
    set_tests_properties(${name} PROPERTIES LABELS "unit;${ARG_LABELS}" TIMEOUT 60)
  endif()
endfunction()
