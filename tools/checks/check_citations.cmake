# Every Markdown file that a source, config or script cites must be in the repository (docs/design.md
# is the reference for the design; nothing may send a reader to a file they cannot open).
# Run as `cmake -DSOURCE_DIR=<tree> -P tools/checks/check_citations.cmake`; the build runs it with the
# layering check. A citation resolves against the tree's root or the citing file's folder.
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "check_citations: pass -DSOURCE_DIR=<source tree>")
endif()

file(GLOB_RECURSE sources RELATIVE "${SOURCE_DIR}"
     "${SOURCE_DIR}/runtime/*" "${SOURCE_DIR}/stages/*" "${SOURCE_DIR}/tools/*" "${SOURCE_DIR}/configs/*"
     "${SOURCE_DIR}/lcmtypes/*" "${SOURCE_DIR}/tests/*" "${SOURCE_DIR}/docs/*" "${SOURCE_DIR}/CMakeLists.txt"
     "${SOURCE_DIR}/README.md")
list(FILTER sources INCLUDE REGEX "(\\.(cpp|hpp|h|txt|cmake|yaml|lcm|idl|md|py|in)|/[a-z-]+)$")
list(FILTER sources EXCLUDE REGEX "(^|/)fixtures/")
set(missing "")
foreach(file IN LISTS sources)
  file(STRINGS "${SOURCE_DIR}/${file}" lines REGEX "[A-Za-z0-9_]\\.md")
  get_filename_component(dir "${SOURCE_DIR}/${file}" DIRECTORY)
  foreach(line IN LISTS lines)
    string(REGEX MATCHALL "[A-Za-z0-9_./-]*[A-Za-z0-9_]\\.md" cited "${line}")
    foreach(path IN LISTS cited)
      if(NOT EXISTS "${SOURCE_DIR}/${path}" AND NOT EXISTS "${dir}/${path}")
        list(APPEND missing "${file}: cites ${path}, which is not in the repository")
      endif()
    endforeach()
  endforeach()
endforeach()
list(REMOVE_DUPLICATES missing)
list(LENGTH missing count)
if(count GREATER 0)
  string(REPLACE ";" "\n  " listing "${missing}")
  message(FATAL_ERROR "citations: ${count} citation(s) of files that are not in the repository:\n  ${listing}")
endif()
message(STATUS "citations: every Markdown file cited in the tree is in it")
