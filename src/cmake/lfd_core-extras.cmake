# Every package that uses lfd_core must share its Eigen ABI: lfd_core is built with -march=native
# (AVX) but pins Eigen's alignment to the SSE2 defaults, so fixed-size members and heap arrays
# agree across the library boundary whatever flags the consumer compiles with.
add_definitions(-DEIGEN_MAX_ALIGN_BYTES=16 -DEIGEN_MALLOC_ALREADY_ALIGNED=1)
