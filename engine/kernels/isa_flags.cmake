# Per-level flags for the kernel files; everything else is built for plain x86-64 so the
# binary runs on any x86-64 CPU and picks its kernels at run time (kernels/dispatch.cpp).
# -ffp-contract=off: GCC before 14 contracts a*b+c into an FMA by default even with
# -std=c++20, so with -mfma the AVX2/AVX-512 kernels silently evaluated a different float
# expression from the SSE kernels and the scalar shape math (different answers on
# ill-conditioned rays, e.g. near a cone's apex). FMAs are written explicitly (xsimd::fma).
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_sse42.cpp PROPERTIES COMPILE_OPTIONS "-msse4.2;-ffp-contract=off")
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx2.cpp PROPERTIES COMPILE_OPTIONS "-mavx2;-mfma;-ffp-contract=off")
# GCC 12 gives false -Wuninitialized/-Wmaybe-uninitialized warnings with AVX-512 (bug 105593).
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx512.cpp PROPERTIES COMPILE_OPTIONS
  "-mavx512f;-mavx512cd;-mavx512dq;-mavx512bw;-mavx512vl;-mfma;-ffp-contract=off;-Wno-uninitialized;-Wno-maybe-uninitialized")
