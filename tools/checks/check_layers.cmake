# The layering check (docs/architecture.md): every quoted project include must point to the same layer
# or a lower one. Run as `cmake -DSOURCE_DIR=<tree> -P tools/checks/check_layers.cmake`; the build runs
# it on every build (target check_layers) and fails listing every violation.
#
# Layers, bottom to top; a file may include the prefixes listed for its folder:
#   stages/foundation/        foundation/                               (no LCM, no PCL)
#   runtime/                  runtime/ fusecal/ (generated lcmtypes)    (no stage, no geometry)
#   stages/formats/           foundation/ runtime/ fusecal/ formats/
#   stages/<stage>/ (core)    foundation/ <stage>/                      (no LCM, no PCL, no bus)
#   stages/node_kit/          foundation/ runtime/ fusecal/ formats/ node_kit/
#   stages/ros2_dds/          foundation/ runtime/ fusecal/ formats/ ros2_dds/   (the ROS 2 nodes' DDS side)
#   stages/<stage>/node/      foundation/ runtime/ fusecal/ formats/ node_kit/ ros2_dds/ <stage>/
#   tools/io/                 foundation/ runtime/ fusecal/ formats/ importers/ scan_io/ visualization/
#                             (PCL only in tools/io/scan_io/*.cpp)
#   tools/sim/                foundation/ runtime/ simulator/           (no LCM, no PCL)
#   tools/cli/                every product layer: stages, nodes, io, sim, pipeline/ (no PCL)
#   tools/bench/, tests/      anything (not checked)
# Quoted includes without one of the project's prefixes (a file beside the includer, generated IDL
# code) are not checked.
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "check_layers: pass -DSOURCE_DIR=<source tree>")
endif()

set(stage_names handeye lidar_icp camera_frontend fusion_odometry stationarity ros2_tf ros2_input)
set(io_prefixes importers scan_io visualization)
set(project_prefixes foundation formats node_kit ros2_dds runtime fusecal pipeline simulator ${io_prefixes} tools support
                     ${stage_names})

# Sets ${out} to the allowed prefixes of `file` (relative path).
function(allowed_prefixes file out)
  if(file MATCHES "^stages/foundation/")
    set(allowed foundation)
  elseif(file MATCHES "^runtime/")
    set(allowed runtime fusecal)
  elseif(file MATCHES "^stages/formats/")
    set(allowed foundation runtime fusecal formats)
  elseif(file MATCHES "^stages/node_kit/")
    set(allowed foundation runtime fusecal formats node_kit)
  elseif(file MATCHES "^stages/ros2_dds/")
    set(allowed foundation runtime fusecal formats ros2_dds)
  elseif(file MATCHES "^stages/([a-z0-9_]+)/node/")
    set(allowed foundation runtime fusecal formats node_kit ros2_dds ${CMAKE_MATCH_1})
  elseif(file MATCHES "^stages/([a-z0-9_]+)/")
    set(allowed foundation ${CMAKE_MATCH_1})
  elseif(file MATCHES "^tools/io/")
    set(allowed foundation runtime fusecal formats ${io_prefixes})
  elseif(file MATCHES "^tools/sim/")
    set(allowed foundation runtime simulator)
  elseif(file MATCHES "^tools/cli/")
    set(allowed foundation runtime fusecal formats node_kit ${stage_names} ${io_prefixes} simulator pipeline)
  endif()
  set(${out} "${allowed}" PARENT_SCOPE)
endfunction()

# System headers a layer must not see: the cores are tested without a bus, and PCL is slow to build.
function(forbidden_system_headers file out)
  if(file MATCHES "^stages/(foundation|formats|node_kit|ros2_dds)/")
    set(banned pcl/)
  elseif(file MATCHES "^stages/[a-z0-9_]+/node/")
    set(banned pcl/)
  elseif(file MATCHES "^stages/")
    set(banned lcm/ pcl/)
  elseif(file MATCHES "^runtime/")
    set(banned pcl/ opencv2/ Eigen/)
  elseif(file MATCHES "^tools/io/scan_io/.*[.]cpp$")
    set(banned "")
  elseif(file MATCHES "^tools/sim/")
    set(banned lcm/ pcl/)
  elseif(file MATCHES "^tools/(io|cli)/")
    set(banned pcl/)
  endif()
  set(${out} "${banned}" PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE sources RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/runtime/*.[hc]pp" "${SOURCE_DIR}/stages/*.[hc]pp"
     "${SOURCE_DIR}/tools/io/*.[hc]pp" "${SOURCE_DIR}/tools/sim/*.[hc]pp" "${SOURCE_DIR}/tools/cli/*.[hc]pp")
set(violations "")
foreach(file IN LISTS sources)
  allowed_prefixes("${file}" allowed)
  forbidden_system_headers("${file}" banned)
  string(REPLACE ";" " " allowed_text "${allowed}")
  file(STRINGS "${SOURCE_DIR}/${file}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[\"<]([^\">]+)[\">].*$" "\\1" header "${line}")
    string(REGEX MATCH "^[A-Za-z0-9_]+/" prefix "${header}")
    if(line MATCHES "#[ \t]*include[ \t]*\"" AND prefix)
      string(REGEX REPLACE "/$" "" prefix "${prefix}")
      list(FIND project_prefixes "${prefix}" known)
      list(FIND allowed "${prefix}" ok)
      if(known GREATER -1 AND ok EQUAL -1)
        list(APPEND violations "${file}: includes \"${header}\" (this layer may include: ${allowed_text})")
      endif()
    elseif(line MATCHES "#[ \t]*include[ \t]*<" AND prefix)
      list(FIND banned "${prefix}" hit)
      if(hit GREATER -1)
        list(APPEND violations "${file}: includes <${header}> (${prefix} is kept out of this layer)")
      endif()
    endif()
  endforeach()
endforeach()

list(LENGTH violations count)
if(count GREATER 0)
  string(REPLACE ";" "\n  " listing "${violations}")
  message(FATAL_ERROR "layering: ${count} include(s) from a lower layer to a higher one "
                      "(docs/architecture.md):\n  ${listing}")
endif()
list(LENGTH sources checked)
message(STATUS "layering: ${checked} files under runtime/, stages/ and tools/{io,sim,cli}/ keep to their layers")
