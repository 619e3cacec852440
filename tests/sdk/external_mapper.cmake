# SPDX-License-Identifier: GPL-3.0-or-later
# The C++ SDK from a user's side: install sonomap into a fresh prefix, build
# examples/external_mapper against it with find_package(sonomap), and run a short `compare` of
# its voxel occupancy map against vdb_gpdf on scenes/smoke.yaml. The example's circle is judged
# by the exact ground truth (eval/), which shares no code with the example.
# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DWORK_DIR=... -DCXX=... [-DSANITIZE=ON] -P this
cmake_minimum_required(VERSION 3.19)  # string(JSON)

function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})  # ours: made below, inside the build tree
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(part core sim audio harness)
  file(GLOB_RECURSE found ${prefix}/include/sonomap/${part}/*.hpp)
  if(NOT found)
    message(FATAL_ERROR "no ${part}/ headers installed under ${prefix}/include/sonomap")
  endif()
endforeach()

set(config -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=Release)
find_program(CCACHE ccache)
if(CCACHE)
  list(APPEND config -DCMAKE_CXX_COMPILER_LAUNCHER=${CCACHE})
endif()
if(SANITIZE)
  list(APPEND config "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -fno-omit-frame-pointer")
endif()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/external_mapper -B ${WORK_DIR}/build ${config})
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j2)
set(exe ${WORK_DIR}/build/occupancy_sonomap)

# Bad input for the user's mapper is bad input like any other: exit 2, nothing written.
execute_process(COMMAND ${exe} --quiet run ${SOURCE_DIR}/scenes/smoke.yaml --frames 1
                        --mapper voxel_occupancy --set mapper.min_hits=0 --out ${WORK_DIR}/bad
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "mapper 'voxel_occupancy'.*min_hits" OR EXISTS ${WORK_DIR}/bad)
  message(FATAL_ERROR "a bad mapper setting: exit ${rc} (expected 2), message: ${err}")
endif()

file(WRITE ${WORK_DIR}/sweep.yaml "name: sdk
frames: 12
seeds: [1]
scenarios:
  - {id: smoke, file: ${SOURCE_DIR}/scenes/smoke.yaml}
variants:
  - {id: occupancy, mapper: voxel_occupancy}
  - {id: gpdf, mapper: vdb_gpdf}
")
step(${exe} --quiet compare ${WORK_DIR}/sweep.yaml --out ${WORK_DIR}/out -j 2)

foreach(variant occupancy gpdf)
  file(READ ${WORK_DIR}/out/runs/smoke-${variant}-s1/summary.json summary)
  string(JSON mapper GET "${summary}" config mapper)
  string(JSON coverage GET "${summary}" metrics circle mean coverage)
  string(JSON rmse GET "${summary}" metrics circle mean rmse)
  message(STATUS "${variant} (${mapper}): circle mean coverage ${coverage}, RMSE ${rmse} m")
  # The camera sees 2 atan(320 / 525) = 62.7 degrees, 0.174 of the circle: a working map
  # covers at least half of that. Surfaces are 0.5 to 3 m away and a voxel centre is within
  # 0.05 sqrt(3) / 2 = 0.043 m of its returns: an RMSE of 0.3 m means a broken map.
  if(NOT coverage GREATER 0.087 OR NOT rmse LESS 0.3)
    message(FATAL_ERROR "${variant}: circle mean coverage ${coverage} (want > 0.087), "
                        "RMSE ${rmse} m (want < 0.3)")
  endif()
endforeach()
if(NOT mapper STREQUAL "vdb_gpdf")
  message(FATAL_ERROR "the gpdf variant ran mapper '${mapper}'")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
