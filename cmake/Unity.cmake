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
