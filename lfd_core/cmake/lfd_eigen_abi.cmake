# The build-wide Eigen rule (DESIGN.md "Build-wide rules"): every translation unit that sees Eigen
# compiles with the same instruction set and Eigen's own alignment defaults. Eigen derives its
# object alignment, heap allocator and packet size from the ISA, so one TU built with
# -march=native (AVX/AVX-512) next to one built for baseline x86-64, or an overridden
# EIGEN_MAX_ALIGN_BYTES, makes objects and heap arrays disagree across library boundaries (an
# aligned 32-byte store into a 16-byte buffer, free() of an Eigen-aligned pointer). SIMD kernels
# pick their ISA at run time instead (lfd_core/lib/segmentation/dtw.cpp, lfd_core/lib/segmentation/clasp_knn.cpp).
#
# lfd_check_eigen_abi() fails the configure when the compile flags of the calling directory or of
# any of its targets break that rule. lfd_core runs it on itself; lfd_core-extras.cmake defers it
# to the end of every package that finds lfd_core.

set(LFD_EIGEN_ABI_FORBIDDEN_FLAGS "-march=" "-mavx" "-mfma" "-msse4" "-mssse3" "-msse3" "-mxop"
    "-mno-sse2")
set(LFD_EIGEN_ABI_FORBIDDEN_DEFINES EIGEN_MAX_ALIGN_BYTES EIGEN_MAX_STATIC_ALIGN_BYTES
    EIGEN_MALLOC_ALREADY_ALIGNED EIGEN_DONT_ALIGN EIGEN_DONT_ALIGN_STATICALLY EIGEN_DONT_VECTORIZE
    EIGEN_UNALIGNED_VECTORIZE EIGEN_ENABLE_AVX512)

function(_lfd_eigen_abi_scan what values)
  foreach(value IN LISTS values)
    foreach(flag IN LISTS LFD_EIGEN_ABI_FORBIDDEN_FLAGS)
      string(FIND "${value}" "${flag}" at)
      if(NOT at EQUAL -1)
        message(FATAL_ERROR "Eigen ABI rule broken: ${what} contains '${value}'. An ISA flag changes "
                            "Eigen's alignment and allocator in some translation units only; use the "
                            "runtime-dispatched kernels (DESIGN.md, Build-wide rules).")
      endif()
    endforeach()
    foreach(define IN LISTS LFD_EIGEN_ABI_FORBIDDEN_DEFINES)
      string(REGEX MATCH "(^|[ ;])(-D)?${define}(=|$|[ ;])" hit "${value}")
      if(hit)
        message(FATAL_ERROR "Eigen ABI rule broken: ${what} sets ${define}. Eigen's alignment must "
                            "stay at its defaults in every translation unit (DESIGN.md, Build-wide rules).")
      endif()
    endforeach()
  endforeach()
endfunction()

function(lfd_check_eigen_abi)
  string(TOUPPER "${CMAKE_BUILD_TYPE}" config)
  _lfd_eigen_abi_scan("CMAKE_CXX_FLAGS" "${CMAKE_CXX_FLAGS};${CMAKE_CXX_FLAGS_${config}}")
  get_directory_property(dir_options COMPILE_OPTIONS)
  get_directory_property(dir_defines COMPILE_DEFINITIONS)
  _lfd_eigen_abi_scan("${PROJECT_NAME}'s directory compile options" "${dir_options};${dir_defines}")
  get_directory_property(targets BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    foreach(property COMPILE_OPTIONS COMPILE_DEFINITIONS INTERFACE_COMPILE_OPTIONS
                     INTERFACE_COMPILE_DEFINITIONS)
      get_target_property(values ${target} ${property})
      if(values)
        _lfd_eigen_abi_scan("target ${target} (${property})" "${values}")
      endif()
    endforeach()
  endforeach()
endfunction()
