# SPDX-License-Identifier: GPL-3.0-or-later
# The Python module from a user's side: `cmake --install` into a fresh prefix, then python3
# imports `sonomap` from <prefix>/SITE (not from the build tree) and loads a scenario through
# the installed libraries.
# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DWORK_DIR=... -DPYTHON=... -DSITE=... -P this
cmake_minimum_required(VERSION 3.18)

file(REMOVE_RECURSE ${WORK_DIR})  # ours: made below, inside the build tree
set(prefix ${WORK_DIR}/prefix)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix}
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc}): ${err}")
endif()

# Only the prefix on the module path: the build tree's module must not be the one imported.
set(ENV{PYTHONPATH} ${prefix}/${SITE})
execute_process(COMMAND ${PYTHON} -c "
import sonomap
print(sonomap.__file__)
scene = sonomap.Scenario('${SOURCE_DIR}/tests/python/wall.yaml')
print(scene.name, len(scene), '%.6f' % scene[0].depth[24, 32])
" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK_DIR})
string(STRIP "${out}" out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^${prefix}/${SITE}/sonomap[^\n]*\\.so\nwall 2 2\\.000000$")
  message(FATAL_ERROR "importing the installed module: exit ${rc}\n${out}\n${err}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
