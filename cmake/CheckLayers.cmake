# The layer rule of libc3po (docs/architecture.md): a file under
# libc3po/<layer>/ may include "c3po/<other>/..." only when <other> is <layer>
# itself or a layer below it (so never "c3po/plugins/..." either), and may not reach into another folder with a
# relative include ("../"). Script mode:
#
#   cmake -DROOT=<libc3po folder> -DRULES_FILE=<file> -P cmake/CheckLayers.cmake
#
# RULES_FILE sets C3PO_LAYER_RULES to "layer:allowed,allowed;..." (written by
# libc3po/CMakeLists.txt from the layers' DEPENDS). Every violation is printed
# as "file: layer L includes "c3po/X/..." (X is not below L)"; the script fails
# if there is any, or if a folder of ROOT with sources is not a known layer.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED ROOT OR NOT DEFINED RULES_FILE)
  message(FATAL_ERROR "usage: cmake -DROOT=DIR -DRULES_FILE=FILE -P CheckLayers.cmake")
endif()
include(${RULES_FILE})

set(layers "")
foreach(rule ${C3PO_LAYER_RULES})
  string(REPLACE ":" ";" parts "${rule}")
  list(GET parts 0 layer)
  list(LENGTH parts n)
  set(allowed_${layer} "")
  if(n GREATER 1)
    list(GET parts 1 allowed)
    string(REPLACE "," ";" allowed_${layer} "${allowed}")
  endif()
  list(APPEND layers ${layer})
endforeach()

set(violations 0)
file(GLOB folders LIST_DIRECTORIES true RELATIVE ${ROOT} ${ROOT}/*)
foreach(folder ${folders})
  if(NOT IS_DIRECTORY ${ROOT}/${folder})
    continue()
  endif()
  file(GLOB_RECURSE files ${ROOT}/${folder}/*.hpp ${ROOT}/${folder}/*.cpp ${ROOT}/${folder}/*.h)
  if(NOT folder IN_LIST layers)
    if(files)
      message(NOTICE "${ROOT}/${folder}: C++ sources in a folder that is not a layer")
      math(EXPR violations "${violations} + 1")
    endif()
    continue()
  endif()
  foreach(file ${files})
    file(STRINGS ${file} includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
    foreach(line ${includes})
      if(line MATCHES "\"c3po/([A-Za-z0-9_]+)/")
        set(target ${CMAKE_MATCH_1})
        if(NOT target IN_LIST allowed_${folder})
          message(NOTICE "${file}: layer ${folder} includes \"c3po/${target}/...\" "
                             "(${target} is not below ${folder}): ${line}")
          math(EXPR violations "${violations} + 1")
        endif()
      elseif(line MATCHES "\"\\.\\./")
        message(NOTICE "${file}: relative include out of its folder: ${line}")
        math(EXPR violations "${violations} + 1")
      endif()
    endforeach()
  endforeach()
endforeach()
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} layer violation(s) in ${ROOT}")
endif()
