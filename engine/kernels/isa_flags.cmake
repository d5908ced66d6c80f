# Per-level flags for the kernel files; everything else is built for plain x86-64 so the
# binary runs on any x86-64 CPU and picks its kernels at run time (kernels/dispatch.cpp).
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_sse42.cpp PROPERTIES COMPILE_OPTIONS "-msse4.2")
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx2.cpp PROPERTIES COMPILE_OPTIONS "-mavx2;-mfma")
# GCC 12 gives false -Wuninitialized/-Wmaybe-uninitialized warnings with AVX-512 (bug 105593).
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx512.cpp PROPERTIES COMPILE_OPTIONS
  "-mavx512f;-mavx512cd;-mavx512dq;-mavx512bw;-mavx512vl;-mfma;-Wno-uninitialized;-Wno-maybe-uninitialized")
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_sse42_accel.cpp PROPERTIES COMPILE_OPTIONS "-msse4.2")
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx2_accel.cpp PROPERTIES COMPILE_OPTIONS "-mavx2;-mfma")
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx512_accel.cpp PROPERTIES COMPILE_OPTIONS
  "-mavx512f;-mavx512cd;-mavx512dq;-mavx512bw;-mavx512vl;-mfma;-Wno-uninitialized;-Wno-maybe-uninitialized")
