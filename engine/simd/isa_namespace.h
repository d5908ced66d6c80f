#pragma once
// The kernel contract for instruction sets (docs/architecture.md, "Kernels and instruction
// sets"): nothing compiled with one level's flags may share a symbol with code compiled with
// other flags. The linker keeps one copy of an inline function or template instantiation for
// every caller, whichever object it comes from, so a shared name could run AVX2 code on the
// SSE2 path (or baseline code in a kernel), at any optimisation level that leaves a call.
//
// STREAMRT_ISA_BEGIN / STREAMRT_ISA_END enclose the functions (and function-only structs such
// as SphereMath) of every header the kernel files include. The kernel files
// (kernels/isa_<level>*.cpp) define STREAMRT_ISA_NAMESPACE as isa_<level> first: there the
// pair opens an inline namespace of that name, so the source still says streamrt::dot or
// simd::select while the symbols are streamrt::isa_avx2::dot, ...; everywhere else it expands
// to nothing. Data types that cross between the engine and the kernels (Vec3T, MaterialT,
// LightT, KernelObject, ShadeJob, the tables) stay outside, with no inline member functions
// the kernels call. Library code the kernels instantiate (std::, xsimd::) cannot be put in a
// namespace: the build renames it per level instead (kernels/isa_rename.cmake).
// tests/architecture/check_isa_symbols.py (ctest architecture_isa_symbols) checks the objects.

#if defined(STREAMRT_ISA_NAMESPACE)
#define STREAMRT_ISA_BEGIN inline namespace STREAMRT_ISA_NAMESPACE {
#define STREAMRT_ISA_END }
// Declared inline here, before any header reopens it (the kernel headers reopen it by name).
namespace streamrt {
STREAMRT_ISA_BEGIN
STREAMRT_ISA_END
}  // namespace streamrt
#else
#define STREAMRT_ISA_BEGIN
#define STREAMRT_ISA_END
#endif
