# Writes the text of `c3po --help` and of `c3po <command> --help` for every
# command to OUT/c3po.txt and OUT/c3po-<command>.txt (man-style help, installed
# under share/doc/c3po/help). Script mode:
#   cmake -DC3PO=<c3po executable> -DOUT=<folder> -P cmake/WriteHelp.cmake
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${C3PO} --help OUTPUT_FILE ${OUT}/c3po.txt COMMAND_ERROR_IS_FATAL ANY)
# The commands are the lines "  NAME   summary" after "Subcommands:".
file(STRINGS ${OUT}/c3po.txt lines)
set(in_commands FALSE)
set(count 0)
foreach(line ${lines})
  if(line MATCHES "^(SUBCOMMANDS|Subcommands):")
    set(in_commands TRUE)
  elseif(in_commands AND line MATCHES "^  ([a-z][a-z0-9-]*)( |$)")
    set(command ${CMAKE_MATCH_1})
    execute_process(COMMAND ${C3PO} ${command} --help OUTPUT_FILE ${OUT}/c3po-${command}.txt
                    COMMAND_ERROR_IS_FATAL ANY)
    math(EXPR count "${count} + 1")
  elseif(in_commands AND NOT line STREQUAL "")
    set(in_commands FALSE)
  endif()
endforeach()
if(count EQUAL 0)
  message(FATAL_ERROR "${C3PO} --help lists no commands under Subcommands:")
endif()
