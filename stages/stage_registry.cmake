# Reads the stage registry (stages/stages.def): the stage names, in start order, into ${names_var} and
# the header of each entry (quoted, as written there) into ${headers_var}. Included by stages/CMakeLists.txt
# and by the layer check (tools/checks/check_layers.cmake), which runs as a script.
function(fusecal_read_stage_registry def_file names_var headers_var)
  file(STRINGS ${def_file} entries REGEX "^FUSECAL_STAGE\\(")
  set(names "")
  set(headers "")
  foreach(entry IN LISTS entries)
    if(NOT entry MATCHES "^FUSECAL_STAGE\\(([a-z0-9_]+), *(\"[^\"]+\")")
      message(FATAL_ERROR "${def_file}: cannot read the entry '${entry}'")
    endif()
    list(APPEND names ${CMAKE_MATCH_1})
    list(APPEND headers ${CMAKE_MATCH_2})
  endforeach()
  set(${names_var} ${names} PARENT_SCOPE)
  set(${headers_var} ${headers} PARENT_SCOPE)
endfunction()
