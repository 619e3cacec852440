# SPDX-License-Identifier: GPL-3.0-or-later
# Fails if a file of the repository (LICENSE aside) refers to the sibling folder that holds the
# maintainers' design notes and data: a fresh clone does not have it, so no build step, test or
# page may point there. Run by CTest: cmake -DSOURCE_DIR=<repository> -P self_contained.cmake
# The files are git's (tracked, and new ones not ignored); without git (an unpacked archive),
# every file in the tree but the build and output folders.
cmake_minimum_required(VERSION 3.18)
set(pattern "\\.\\./shared")  # a regex, so this file does not match itself
execute_process(COMMAND git ls-files --cached --others --exclude-standard
  WORKING_DIRECTORY "${SOURCE_DIR}" OUTPUT_VARIABLE tracked RESULT_VARIABLE git_status ERROR_QUIET)
if(git_status EQUAL 0 AND NOT tracked STREQUAL "")
  string(REPLACE "\n" ";" files "${tracked}")
else()
  file(GLOB_RECURSE files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/*")
  list(FILTER files EXCLUDE REGEX "^(\\.git|build[^/]*|demo-out|out)/")
endif()
list(REMOVE_ITEM files "LICENSE")
set(offenders "")
set(checked 0)
foreach(file IN LISTS files)
  if(file STREQUAL "" OR NOT EXISTS "${SOURCE_DIR}/${file}" OR IS_DIRECTORY "${SOURCE_DIR}/${file}")
    continue()
  endif()
  math(EXPR checked "${checked} + 1")
  file(STRINGS "${SOURCE_DIR}/${file}" hits REGEX "${pattern}")
  foreach(hit IN LISTS hits)
    string(APPEND offenders "  ${file}: ${hit}\n")
  endforeach()
endforeach()
if(checked LESS 20)
  message(FATAL_ERROR "only ${checked} files found under ${SOURCE_DIR}: wrong directory?")
endif()
if(offenders)
  message(FATAL_ERROR "files refer to the folder beside the repository:\n${offenders}")
endif()
message(STATUS "${checked} files checked: none refers to a folder outside the repository")
