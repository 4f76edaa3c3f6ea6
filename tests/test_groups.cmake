# sphshell_test_group(<group entry> <group variable> <members variable> <source variable>)
# The generated source of a group of test files compiled as one translation
# unit. <group entry> is "<group>:<file>,<file>,..." (files of the current
# source directory, without .cpp); the group's name, its member files and
# the generated source's path are returned in the three variables. The
# source first includes every header its files include, then each file inside
# a namespace of its own, so that one file's helpers and using-directives
# never meet another's. A file's #include lines change the generated source:
# the project is configured again when a member changes.
function(sphshell_test_group entry group_variable members_variable source_variable)
  string(REPLACE ":" ";" entry "${entry}")
  list(GET entry 0 group)
  list(GET entry 1 members)
  string(REPLACE "," ";" members "${members}")
  set(headers "")
  set(bodies "")
  foreach(name IN LISTS members)
    set(source ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
    if(NOT EXISTS ${source})
      message(FATAL_ERROR "test group ${group} lists ${name}, but ${source} does not exist")
    endif()
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${source})
    file(STRINGS ${source} includes REGEX "^#include ")
    list(APPEND headers ${includes})
    string(APPEND bodies "namespace ${name}_cases {\n#include \"${source}\"\n}  // namespace ${name}_cases\n")
  endforeach()
  list(REMOVE_DUPLICATES headers)
  # <omp.h> is included under #ifdef _OPENMP by the files that use it.
  list(FILTER headers EXCLUDE REGEX "<omp\\.h>")
  list(JOIN headers "\n" headers)
  set(unity_source ${CMAKE_CURRENT_BINARY_DIR}/${group}.cpp)
  file(CONFIGURE OUTPUT ${unity_source}
       CONTENT "// Generated (tests/test_groups.cmake): the test files of group ${group}.\n${headers}\n#ifdef _OPENMP\n#include <omp.h>\n#endif\n\n${bodies}"
       @ONLY)
  set(${group_variable} ${group} PARENT_SCOPE)
  set(${members_variable} ${members} PARENT_SCOPE)
  set(${source_variable} ${unity_source} PARENT_SCOPE)
endfunction()
