# Per-level flags for the kernel files; everything else is built for plain x86-64 so the
# binary runs on any x86-64 CPU and picks its kernels at run time (kernels/dispatch.cpp).
# -ffp-contract=off: GCC before 14 contracts a*b+c into an FMA by default even with
# -std=c++20, so with -mfma the AVX2/AVX-512 kernels silently evaluated a different float
# expression from the SSE kernels and the scalar shape math (different answers on
# ill-conditioned rays, e.g. near a cone's apex). FMAs are written explicitly (xsimd::fma).
# GCC 12 gives false -Wuninitialized/-Wmaybe-uninitialized warnings with AVX-512 (bug 105593).
set(STREAMRT_SSE42_FLAGS "-msse4.2;-ffp-contract=off")
set(STREAMRT_AVX2_FLAGS "-mavx2;-mfma;-ffp-contract=off")
# Unoptimised builds (Debug) compile the AVX-512 files at -Og: at -O0 GCC 12 defines some
# AVX-512 intrinsics as macros with casts, and xsimd 8.1's integer select (reached through
# xsimd::pow) then fails to compile.
set(STREAMRT_AVX512_FLAGS
  "-mavx512f;-mavx512cd;-mavx512dq;-mavx512bw;-mavx512vl;-mfma;-ffp-contract=off;-Wno-uninitialized;-Wno-maybe-uninitialized;$<$<CONFIG:Debug>:-Og>")
foreach(suffix "" "_accel")
  set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_sse42${suffix}.cpp PROPERTIES COMPILE_OPTIONS "${STREAMRT_SSE42_FLAGS}")
  set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx2${suffix}.cpp PROPERTIES COMPILE_OPTIONS "${STREAMRT_AVX2_FLAGS}")
  set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/kernels/isa_avx512${suffix}.cpp PROPERTIES COMPILE_OPTIONS "${STREAMRT_AVX512_FLAGS}")
endforeach()
