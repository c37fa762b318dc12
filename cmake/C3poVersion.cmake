# The versions of c3po, from their single sources:
#   PROJECT_VERSION (project() in the top CMakeLists.txt): the release, in
#     semantic versioning; c3po --version, the CMake package, c3po.pc, the .deb.
#   C3PO_PLUGIN_ABI_VERSION: the C plugin ABI, defined in
#     plugins/include/c3po/plugins/plugin_api.h (the header plugins compile
#     against) and read from there.
# Both go to the generated public header c3po/base/version.hpp.
set(C3PO_PLUGIN_API_HEADER ${PROJECT_SOURCE_DIR}/plugins/include/c3po/plugins/plugin_api.h)
file(STRINGS ${C3PO_PLUGIN_API_HEADER} abi_line REGEX "^#define C3PO_PLUGIN_ABI_VERSION [0-9]+$")
if(NOT abi_line MATCHES "^#define C3PO_PLUGIN_ABI_VERSION ([0-9]+)$")
  message(FATAL_ERROR "${C3PO_PLUGIN_API_HEADER}: no line '#define C3PO_PLUGIN_ABI_VERSION <number>'")
endif()
set(C3PO_PLUGIN_ABI_VERSION ${CMAKE_MATCH_1})
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${C3PO_PLUGIN_API_HEADER})

set(C3PO_GENERATED_INCLUDE_DIR ${PROJECT_BINARY_DIR}/generated/include)
configure_file(${PROJECT_SOURCE_DIR}/cmake/templates/version.hpp.in
               ${C3PO_GENERATED_INCLUDE_DIR}/c3po/base/version.hpp @ONLY)
