# epichead_module(NAME <lib> DEPS <targets...> [PCH <parts...>]): one static library per
# top-level folder, sources from src/, public headers from include/. PCH: a precompiled header
# of the libraries named (epichead_precompile, PrecompiledHeaders.cmake). A module without
# sources yet is an interface target, so the dependency graph stays the same while it is being
# written.
# Every module is also epichead::<name without the prefix> (the name an installed package's
# users link, docs/install.md) and is installed with its headers.
include(GNUInstallDirs)
function(epichead_module)
  cmake_parse_arguments(M "" "NAME" "DEPS;PCH" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  set(include_dirs $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(NOT sources)
    add_library(${M_NAME} INTERFACE)
    target_include_directories(${M_NAME} INTERFACE ${include_dirs})
    target_link_libraries(${M_NAME} INTERFACE ${M_DEPS})
  else()
    add_library(${M_NAME} STATIC ${sources})
    target_include_directories(${M_NAME} PUBLIC ${include_dirs} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_link_libraries(${M_NAME} PUBLIC ${M_DEPS})
    if(DEFINED M_PCH)
      epichead_precompile(${M_NAME} ${M_PCH})
    endif()
  endif()
  epichead_install_library(${M_NAME} ${CMAKE_CURRENT_SOURCE_DIR}/include)
endfunction()

# epichead_install_library(<lib> <include dir>): the epichead::<name> alias, and the library
# and its public headers in the install tree, in the export set of epicheadConfig.cmake.
function(epichead_install_library name include_dir)
  string(REGEX REPLACE "^epichead_" "" short ${name})
  add_library(epichead::${short} ALIAS ${name})
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${short})
  install(TARGETS ${name} EXPORT epicheadTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${include_dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
