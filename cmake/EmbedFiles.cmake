# Embeds files into a library as functions returning their bytes (cmake/embed_files.cmake).

set(KARTOGRAF_EMBED_FILES_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_files.cmake)

# kartograf_embed_files(<out_cpp> NAMESPACE <ns> ENTRIES <function=path>...)
function(kartograf_embed_files out_cpp)
  cmake_parse_arguments(ARG "" "NAMESPACE" "ENTRIES" ${ARGN})
  set(paths "")
  foreach(entry IN LISTS ARG_ENTRIES)
    string(REGEX REPLACE "^[^=]*=" "" path "${entry}")
    list(APPEND paths ${path})
  endforeach()
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DNAMESPACE=${ARG_NAMESPACE}
            "-DENTRIES=${ARG_ENTRIES}" -P ${KARTOGRAF_EMBED_FILES_SCRIPT}
    DEPENDS ${paths} ${KARTOGRAF_EMBED_FILES_SCRIPT}
    COMMENT "Embedding files: ${out_cpp}"
    VERBATIM)
endfunction()
