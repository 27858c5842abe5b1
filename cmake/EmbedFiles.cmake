# epichead_embed_files(TARGET <lib> OUTPUT <file.cpp> BASE_DIR <dir> FILES <paths...>)
# Builds the files into <lib>: OUTPUT (in the build tree) is generated at build time by
# embed_files.cmake and holds each file's bytes and its name (its path relative to BASE_DIR,
# with '/'), and is regenerated when any of the files changes. The table's layout is
# declared by the target's private builtin_asset_table.h, which OUTPUT includes.
set(EPICHEAD_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_files.cmake)
function(epichead_embed_files)
  cmake_parse_arguments(E "" "TARGET;OUTPUT;BASE_DIR" "FILES" ${ARGN})
  set(names "")
  set(paths "")
  foreach(file ${E_FILES})
    get_filename_component(path ${file} ABSOLUTE)
    file(RELATIVE_PATH name ${E_BASE_DIR} ${path})
    list(APPEND names ${name})
    list(APPEND paths ${path})
  endforeach()
  # The list of names and paths goes through a file: no command-line quoting of lists.
  set(manifest ${E_OUTPUT}.files)
  set(lines "")
  foreach(name path IN ZIP_LISTS names paths)
    string(APPEND lines "${name}\t${path}\n")
  endforeach()
  file(CONFIGURE OUTPUT ${manifest} CONTENT "${lines}" @ONLY)  # rewritten only when it changes
  add_custom_command(
    OUTPUT ${E_OUTPUT}
    COMMAND ${CMAKE_COMMAND} -DMANIFEST=${manifest} -DOUTPUT=${E_OUTPUT} -P ${EPICHEAD_EMBED_SCRIPT}
    DEPENDS ${paths} ${manifest} ${EPICHEAD_EMBED_SCRIPT}
    COMMENT "Embedding ${CMAKE_CURRENT_SOURCE_DIR} files into ${E_TARGET}"
    VERBATIM)
  target_sources(${E_TARGET} PRIVATE ${E_OUTPUT})
endfunction()
