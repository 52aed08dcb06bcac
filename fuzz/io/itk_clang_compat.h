// Debian's ITK 5.2 headers accept only GCC: itk_compiler_detection.h ends in "#error
// Unsupported compiler" for clang, which libFuzzer needs. Force-included (-include) before
// anything else in a clang build, this header lets ITK's detection run once as if for GCC 12
// (clang implements everything that header then assumes), then restores clang's macros, so the
// rest of the translation unit sees clang as it is.
#pragma once
#if defined(__clang__) && defined(__cplusplus)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wbuiltin-macro-redefined"
#pragma push_macro("__clang__")
#pragma push_macro("__GNUC__")
#pragma push_macro("__GNUC_MINOR__")
#undef __clang__
#undef __GNUC__
#undef __GNUC_MINOR__
#define __GNUC__ 12
#define __GNUC_MINOR__ 2
#include <itk_compiler_detection.h>
#pragma pop_macro("__GNUC_MINOR__")
#pragma pop_macro("__GNUC__")
#pragma pop_macro("__clang__")
#pragma clang diagnostic pop
#endif
