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

# Eigen's alignment (EIGEN_MAX_ALIGN_BYTES) decides the layout of fixed-size
# Eigen members in c3po's structs, and it follows the instruction set (16 for
# SSE, 32 with AVX, 64 with AVX-512). A program that uses the installed
# libraries must agree with the flags they were built with, whatever its own
# flags: the exported targets carry the value measured here
# (cmake/C3poInstall.cmake). Eigen allows a larger bound than the ideal one.
function(c3po_measure_eigen_alignment result)
  include(CheckCXXSourceCompiles)
  find_path(c3po_eigen_include Eigen/Core PATH_SUFFIXES eigen3 REQUIRED)
  set(CMAKE_REQUIRED_INCLUDES ${c3po_eigen_include})
  # The cached answers are per flag set (C3PO_NATIVE may be toggled later).
  set(flavour PORTABLE)
  if(C3PO_NATIVE AND C3PO_HAS_MARCH_NATIVE AND NOT C3PO_FUZZ)
    set(CMAKE_REQUIRED_FLAGS -march=native)
    set(flavour NATIVE)
  endif()
  set(CMAKE_REQUIRED_QUIET ON)
  foreach(bytes 64 32 16 0)
    check_cxx_source_compiles("#include <Eigen/Core>
static_assert(EIGEN_MAX_ALIGN_BYTES == ${bytes}, \"\");
int main() { return 0; }" C3PO_EIGEN_MAX_ALIGN_BYTES_${flavour}_IS_${bytes})
    if(C3PO_EIGEN_MAX_ALIGN_BYTES_${flavour}_IS_${bytes})
      set(${result} ${bytes} PARENT_SCOPE)
      return()
    endif()
  endforeach()
  message(FATAL_ERROR "cannot measure Eigen's EIGEN_MAX_ALIGN_BYTES")
endfunction()
