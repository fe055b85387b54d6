# SPDX-License-Identifier: MIT
# The project's Python venv (made by scripts/setup.sh) and the native packages it carries:
# Box2D 3.1.1 (pyb2d3 wheel) and LCM 1.5.3 (lcm wheel) install a CMake-usable prefix in site-packages.
set(POUR_VENV "${PROJECT_SOURCE_DIR}/.venv" CACHE PATH "Python venv made by scripts/setup.sh")
set(POUR_PYTHON "${POUR_VENV}/bin/python")
if(NOT EXISTS "${POUR_PYTHON}")
  message(FATAL_ERROR "No venv at ${POUR_VENV}: run scripts/setup.sh first")
endif()
execute_process(
  COMMAND "${POUR_PYTHON}" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])"
  OUTPUT_VARIABLE POUR_SITE_PACKAGES OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
# Debian's CMake does not look in lib64 for package configs.
list(APPEND CMAKE_PREFIX_PATH "${POUR_SITE_PACKAGES}" "${POUR_SITE_PACKAGES}/lib64/cmake")
