# Every package that uses lfd_core shares its Eigen ABI: no ISA flags, Eigen's alignment defaults.
# Checked at the end of the package's CMakeLists (after its targets exist).
include(${CMAKE_CURRENT_LIST_DIR}/lfd_eigen_abi.cmake)
cmake_language(DEFER DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} CALL lfd_check_eigen_abi)
