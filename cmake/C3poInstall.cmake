# cmake --install (GNUInstallDirs, relocatable: every installed path is
# relative to the prefix), the CMake package c3po (find_package(c3po 0.2)),
# c3po.pc, and the Debian package (cpack -G DEB). docs/install.md describes the
# result; scripts/check-install.sh checks it.
#
# The libraries are static (position-independent): c3po's C++ API is not an
# ABI promise, so programs link the layers they use into themselves; the one
# stable binary interface is the C plugin API (plugin_api.h), which plugins
# use without linking any c3po code.
include(CMakePackageConfigHelpers)

set(C3PO_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/c3po)
set(C3PO_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/c3po)

# The executable, the libraries (each layer, c3po::core, the plugins and their
# detectors, the header-only c3po::plugin_api).
get_property(C3PO_INSTALL_LAYERS GLOBAL PROPERTY C3PO_LAYERS)
set(C3PO_INSTALL_TARGETS c3po_core c3po_plugins c3po_plugin_api)
foreach(layer ${C3PO_INSTALL_LAYERS})
  list(APPEND C3PO_INSTALL_TARGETS c3po_${layer})
endforeach()
# The built-in detectors: every c3po_detector_<name> that c3po::plugins links
# (a new detector in plugins/<name>/ is installed without listing it here).
# Include folders given as plain source paths become BUILD_INTERFACE ones, with
# the installed include folder as their INSTALL_INTERFACE.
set(C3PO_INSTALL_DETECTOR_HEADER_DIRS "")
get_target_property(plugin_links c3po_plugins LINK_LIBRARIES)
foreach(detector ${plugin_links})
  if(NOT detector MATCHES "^c3po_detector_(.+)$" OR NOT TARGET ${detector})
    continue()
  endif()
  list(APPEND C3PO_INSTALL_TARGETS ${detector})
  set_target_properties(${detector} PROPERTIES EXPORT_NAME detector_${CMAKE_MATCH_1})
  get_target_property(dirs ${detector} INTERFACE_INCLUDE_DIRECTORIES)
  set(interface_dirs "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  foreach(dir ${dirs})
    if(dir MATCHES "^\\$<BUILD_INTERFACE:(.*)>$")
      list(APPEND C3PO_INSTALL_DETECTOR_HEADER_DIRS ${CMAKE_MATCH_1})
      list(APPEND interface_dirs "${dir}")
    elseif(dir MATCHES "^\\$<")
      continue()   # the INSTALL_INTERFACE, added once above
    else()
      list(APPEND C3PO_INSTALL_DETECTOR_HEADER_DIRS ${dir})
      list(APPEND interface_dirs "$<BUILD_INTERFACE:${dir}>")
    endif()
  endforeach()
  set_property(TARGET ${detector} PROPERTY INTERFACE_INCLUDE_DIRECTORIES "${interface_dirs}")
endforeach()
# Programs built against the installed libraries use the Eigen alignment they
# were built with (cmake/C3poCompilerSettings.cmake).
c3po_measure_eigen_alignment(C3PO_EIGEN_MAX_ALIGN_BYTES)
target_compile_definitions(c3po_base INTERFACE
  $<INSTALL_INTERFACE:EIGEN_MAX_ALIGN_BYTES=${C3PO_EIGEN_MAX_ALIGN_BYTES}>)
install(TARGETS c3po RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS ${C3PO_INSTALL_TARGETS} EXPORT c3poTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# Public headers only: each layer's include/ folder (never src/), the plugin
# headers, and the generated version header.
get_property(C3PO_INSTALL_HEADER_DIRS GLOBAL PROPERTY C3PO_INSTALL_HEADER_DIRS)
list(APPEND C3PO_INSTALL_HEADER_DIRS ${PROJECT_SOURCE_DIR}/plugins/include ${C3PO_INSTALL_DETECTOR_HEADER_DIRS})
list(REMOVE_DUPLICATES C3PO_INSTALL_HEADER_DIRS)
foreach(dir ${C3PO_INSTALL_HEADER_DIRS})
  install(DIRECTORY ${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()
install(FILES ${C3PO_GENERATED_INCLUDE_DIR}/c3po/base/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/c3po/base)

# The bundled objects (c3po finds them in <prefix>/share/c3po/annotations
# relative to its own location, cli/bundled_objects.cpp).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/annotations/ DESTINATION ${C3PO_INSTALL_DATADIR}/annotations
        FILES_MATCHING PATTERN "*.json" PATTERN "*.obj" PATTERN "README.md"
        PATTERN "generator" EXCLUDE)

# Documentation: README, CHANGELOG, docs/*.md, and the text of every
# `c3po ... --help`, written at install time by the installed executable's
# build (cmake/WriteHelp.cmake).
file(GLOB C3PO_DOCS ${PROJECT_SOURCE_DIR}/docs/*.md)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md ${C3PO_DOCS}
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(CODE "execute_process(COMMAND \"${CMAKE_COMMAND}\" -DC3PO=$<TARGET_FILE:c3po>
                                      -DOUT=${PROJECT_BINARY_DIR}/help
                                      -P \"${PROJECT_SOURCE_DIR}/cmake/WriteHelp.cmake\"
                              COMMAND_ERROR_IS_FATAL ANY)")
install(DIRECTORY ${PROJECT_BINARY_DIR}/help/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/help)

# The CMake package.
install(EXPORT c3poTargets NAMESPACE c3po:: FILE c3poTargets.cmake DESTINATION ${C3PO_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/templates/c3poConfig.cmake.in
  ${PROJECT_BINARY_DIR}/c3poConfig.cmake
  INSTALL_DESTINATION ${C3PO_INSTALL_CMAKEDIR}
  PATH_VARS C3PO_INSTALL_DATADIR)
# 0.x: a minor release may break the C++ API, so 0.2 accepts 0.2.x only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/c3poConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/c3poConfig.cmake ${PROJECT_BINARY_DIR}/c3poConfigVersion.cmake
        DESTINATION ${C3PO_INSTALL_CMAKEDIR})

# pkg-config: c3po.pc, relocatable (prefix relative to the .pc file). Static
# libraries, so their dependencies are Requires and Libs, not .private.
set(C3PO_PC_LIBS "-lc3po_plugins")
foreach(target ${C3PO_INSTALL_TARGETS})
  if(target MATCHES "^c3po_detector_")
    string(APPEND C3PO_PC_LIBS " -l${target}")
  endif()
endforeach()
set(C3PO_PC_LAYERS ${C3PO_INSTALL_LAYERS})
list(REVERSE C3PO_PC_LAYERS)   # top layer first: a static link resolves downwards
foreach(layer ${C3PO_PC_LAYERS})
  string(APPEND C3PO_PC_LIBS " -lc3po_${layer}")
endforeach()
file(RELATIVE_PATH C3PO_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" C3PO_PC_TO_PREFIX "${C3PO_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/templates/c3po.pc.in ${PROJECT_BINARY_DIR}/c3po.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/c3po.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The Debian package: cpack -G DEB in the build folder -> c3po_<version>_<arch>.deb.
# Depends: the shared libraries the executable needs, found by dpkg-shlibdeps
# (dpkg-dev); the -dev packages needed to build against the headers are
# Suggests (c3po --help and the CLI need none of them).
set(CPACK_PACKAGE_NAME c3po)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_CONTACT "c3po maintainers <c3po@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "libeigen3-dev, libnanoflann-dev, nlohmann-json3-dev, libassimp-dev, libspng-dev, pkg-config, cmake")
set(CPACK_GENERATOR DEB)
include(CPack)
