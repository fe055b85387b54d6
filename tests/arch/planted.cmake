# SPDX-License-Identifier: MIT
# The architecture check against planted violations (ctest architecture_planted, label arch): copies the
# source folders the build's targets compile (firmware/, host_sim/) to WORK, points a copy of the target
# graph and of the include folders at it, and plants one violation at a time. The check must pass on the
# clean copy and fail on each plant, naming the file, the include and what it resolved to.
# Usage: cmake -DGRAPH=<build>/architecture/targets.cmake -DCHECK=cmake/CheckArchitecture.cmake
#              -DWORK=<temp folder> -P tests/arch/planted.cmake
cmake_minimum_required(VERSION 3.25)
foreach(v GRAPH CHECK WORK)
  if(NOT ${v})
    message(FATAL_ERROR "planted: -D${v}= is required")
  endif()
endforeach()
include("${GRAPH}")
cmake_path(GET GRAPH PARENT_PATH graph_dir)
set(src "${POUR_SOURCE_DIR}")
set(tree "${WORK}/tree")
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${tree}")
file(COPY "${src}/firmware" "${src}/host_sim" DESTINATION "${tree}")
file(READ "${GRAPH}" graph_text)
file(READ "${graph_dir}/includes.cmake" includes_text)
foreach(folder firmware host_sim)
  string(REPLACE "${src}/${folder}" "${tree}/${folder}" graph_text "${graph_text}")
  string(REPLACE "${src}/${folder}" "${tree}/${folder}" includes_text "${includes_text}")
endforeach()
string(REPLACE "set(POUR_SOURCE_DIR [==[${src}]==])" "set(POUR_SOURCE_DIR [==[${tree}]==])"
       graph_text "${graph_text}")

# check(<name> <graph text> <includes text> <expect: PASS or a regex the failure must match>)
function(check name graph includes expect)
  set(dir "${WORK}/${name}")
  file(WRITE "${dir}/targets.cmake" "${graph}")
  file(WRITE "${dir}/includes.cmake" "${includes}")
  execute_process(COMMAND "${CMAKE_COMMAND}" "-DGRAPH=${dir}/targets.cmake" -P "${CHECK}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  string(REGEX REPLACE "[ \n]+" " " flat "${out}")
  if(expect STREQUAL "PASS")
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "planted/${name}: the check fails on the clean copy:\n${out}")
    endif()
  elseif(rc EQUAL 0)
    message(FATAL_ERROR "planted/${name}: the check passes with the plant in place:\n${out}")
  elseif(NOT flat MATCHES "${expect}")
    message(FATAL_ERROR "planted/${name}: the check fails, but not with /${expect}/:\n${out}")
  endif()
  message(STATUS "planted/${name}: as expected")
endfunction()

# plant(<file relative to the tree> <line>) / unplant(<file>): append an #include, restore the original.
function(plant file line)
  file(APPEND "${tree}/${file}" "\n${line}\n")
endfunction()
function(unplant file)
  file(COPY_FILE "${src}/${file}" "${tree}/${file}")
endfunction()

check(clean "${graph_text}" "${includes_text}" PASS)

# An include that climbs out of the port into the simulator's private header.
set(ctl "firmware/ports/linux/controller.c")
plant("${ctl}" "#include \"../../../host_sim/physics/foc_drive.hpp\"")
check(relative_include "${graph_text}" "${includes_text}"
      "firmware -> simulator/tools: ${ctl} includes '../../../host_sim/physics/foc_drive.hpp' = host_sim/physics/foc_drive.hpp \\(target pour_linux_port\\)")
unplant("${ctl}")

# A bare header name that resolves into host_sim/ through an include folder a CMakeLists gave the port.
plant("${ctl}" "#include \"motor_model.hpp\"")
string(REPLACE "set(POUR_T_pour_linux_port_INCS [==[" "set(POUR_T_pour_linux_port_INCS [==[${tree}/host_sim/physics;"
       planted_includes "${includes_text}")
check(include_folder "${graph_text}" "${planted_includes}"
      "includes 'motor_model.hpp' = host_sim/physics/motor_model.hpp \\(target pour_linux_port\\).*pour_linux_port \\(firmware/ports/linux\\) compiles or includes from host_sim/physics")
unplant("${ctl}")

# A header under firmware/ that names tools/, even when nothing resolves it.
set(hal "firmware/ports/hal/port_tick.h")
plant("${hal}" "#include \"tools/pour/core.h\"")
check(named_path "${graph_text}" "${includes_text}"
      "firmware -> simulator/tools: ${hal} names 'tools/pour/core.h'")
unplant("${hal}")

# A host target that compiles a Cortex-M4 driver.
string(REPLACE "set(POUR_T_poursim_objects_SRCS [==[" "set(POUR_T_poursim_objects_SRCS [==[${tree}/firmware/ports/cortex-m4/drivers/fdcan.c;"
       planted_graph "${graph_text}")
check(cm4_in_host "${planted_graph}" "${includes_text}"
      "cortex-m4 -> host target: poursim_objects \\(host_sim\\) compiles or includes from firmware/ports/cortex-m4/drivers/fdcan.c")

# The portable code reaching into a port.
set(flow "firmware/ports/common/calibration_flow.c")
plant("${flow}" "#include \"board_drive.h\"")
check(common_to_port "${graph_text}" "${includes_text}"
      "common -> a port: ${flow} includes 'board_drive.h' = firmware/ports/cortex-m4/board/board_drive.h")
unplant("${flow}")

# host_sim's rooms: the physics reaching up into the bridge, the bridge into the checks, the library into
# the CLI (each through the include folders libpoursim's objects already take).
set(fluid "host_sim/physics/fluid.cpp")
plant("${fluid}" "#include \"controllers.hpp\"")
check(physics_to_bridge "${graph_text}" "${includes_text}"
      "physics -> a room above: ${fluid} includes 'controllers.hpp' = host_sim/bridge/controllers.hpp \\(target poursim_objects\\)")
unplant("${fluid}")
set(rollout "host_sim/bridge/rollout.cpp")
plant("${rollout}" "#include \"motor_checks.hpp\"")
check(bridge_to_checks "${graph_text}" "${includes_text}"
      "bridge -> a room above: ${rollout} includes 'motor_checks.hpp' = host_sim/checks/motor_checks.hpp")
unplant("${rollout}")
set(checks "host_sim/checks/checks.cpp")
plant("${checks}" "#include \"summary.hpp\"")
check(library_to_cli "${graph_text}" "${includes_text}"
      "libpoursim -> cli: ${checks} includes 'summary.hpp' = host_sim/cli/summary.hpp \\(target poursim_objects\\)")
unplant("${checks}")

file(REMOVE_RECURSE "${WORK}")
