# SPDX-License-Identifier: GPL-3.0-or-later
# Writes the code version file (cmake/version.cpp.in) with the source tree's `git describe`.
# Run at configure time and again by every build (harness/CMakeLists.txt), so a result names
# the commit it was built from, not the one CMake was first configured at. configure_file()
# leaves the file untouched when the text is the same, so only a new version recompiles it.
# Inputs: SOURCE_DIR, TEMPLATE, OUTPUT, PROJECT_VERSION.
execute_process(COMMAND git describe --always --dirty --tags
  WORKING_DIRECTORY ${SOURCE_DIR} OUTPUT_VARIABLE SONOMAP_GIT_VERSION
  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT SONOMAP_GIT_VERSION)
  set(SONOMAP_GIT_VERSION "unknown")
endif()
configure_file(${TEMPLATE} ${OUTPUT} @ONLY)
