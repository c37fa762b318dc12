# Compiler settings shared by every c3po target.
if(C3PO_USE_CCACHE)
  find_program(C3PO_CCACHE ccache)
  if(C3PO_CCACHE)
    set(CMAKE_CXX_COMPILER_LAUNCHER ${C3PO_CCACHE})
  endif()
endif()

if(C3PO_NATIVE AND NOT C3PO_FUZZ)
  include(CheckCXXCompilerFlag)
  check_cxx_compiler_flag(-march=native C3PO_HAS_MARCH_NATIVE)
  if(C3PO_HAS_MARCH_NATIVE)
    add_compile_options(-march=native)
  endif()
endif()

if(C3PO_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

if(C3PO_FUZZ)
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# c3po_set_warnings(target): warnings are per target, never global.
function(c3po_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter
                         $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
endfunction()
