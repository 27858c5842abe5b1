# Installing and packaging (docs/install.md): the program, the static libraries and their
# headers, a CMake package (find_package(epichead), targets epichead::<module>), a pkg-config
# file, and a Debian package made by CPack (./dev package). The program, the libraries
# (firmware_iface::program_version()), the package config and the .deb share PROJECT_VERSION.
include(CMakePackageConfigHelpers)
set(epichead_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/epichead)
install(EXPORT epicheadTargets NAMESPACE epichead:: DESTINATION ${epichead_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/epicheadConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/epicheadConfig.cmake INSTALL_DESTINATION ${epichead_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/epicheadConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/epicheadConfig.cmake ${PROJECT_BINARY_DIR}/epicheadConfigVersion.cmake
        DESTINATION ${epichead_cmake_dir})
# The prefix is filled in at install time (cmake --install --prefix may differ from the configured one).
configure_file(${PROJECT_SOURCE_DIR}/cmake/epichead.pc.in ${PROJECT_BINARY_DIR}/epichead.pc.in @ONLY)
install(CODE "
  file(READ \"${PROJECT_BINARY_DIR}/epichead.pc.in\" pc)
  string(REPLACE \"%PREFIX%\" \"\${CMAKE_INSTALL_PREFIX}\" pc \"\${pc}\")
  file(WRITE \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig/epichead.pc\" \"\${pc}\")")
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
# Debian's machine-readable copyright file (DEP-5), where Debian tools and users look for the
# licence: the header, then LICENSE's own text.
file(READ ${PROJECT_SOURCE_DIR}/LICENSE license_text)
string(REGEX REPLACE "\n\n" "\n.\n" license_text "${license_text}")
string(REGEX REPLACE "\n([^\n])" "\n \\1" license_text "${license_text}")
file(WRITE ${PROJECT_BINARY_DIR}/copyright
     "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/\n"
     "Upstream-Name: epichead\n\n"
     "Files: *\nCopyright: 2026 the epichead authors\nLicense: BSD-3-Clause\n ${license_text}\n")
install(FILES ${PROJECT_BINARY_DIR}/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The Debian package. Its dependencies: the "libraries" section of deps/debian-packages.txt
# (what the installed headers and static libraries need to build against) and, found by
# dpkg-shlibdeps, the shared libraries the program runs with.
file(STRINGS ${PROJECT_SOURCE_DIR}/deps/debian-packages.txt dep_lines)
set(section "")
set(package_depends "")
foreach(line IN LISTS dep_lines)
  if(line MATCHES "^# == (.+) ==")
    set(section "${CMAKE_MATCH_1}")
  elseif(section MATCHES "^libraries" AND NOT line MATCHES "^#" AND NOT line STREQUAL "")
    list(APPEND package_depends "${line}")
  endif()
endforeach()
# The Python module is built for one Python (its file is named cpython-3XY): the package works
# with that minor version only, as Debian's own extension modules say.
if(EPICHEAD_PYTHON AND Python_VERSION_MINOR)
  math(EXPR python_next_minor "${Python_VERSION_MINOR} + 1")
  list(APPEND package_depends "python3 (>= ${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}~)"
       "python3 (<< ${Python_VERSION_MAJOR}.${python_next_minor})")
endif()
list(JOIN package_depends ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME epichead)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "the epichead authors")
set(CPACK_PACKAGE_CONTACT "the epichead authors <epichead@users.noreply.github.com>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Model-based tracking, IMU fusion and pan/tilt head control for a camera head")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "Model-based tracking, IMU fusion and pan/tilt head control for a camera head
 The onboard program of a camera head on a walking robot, its C++ libraries, CMake and
 pkg-config files, and the Python module. Licence: BSD-3-Clause
 (/usr/share/doc/epichead/copyright).")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
