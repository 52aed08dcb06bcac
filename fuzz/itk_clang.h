// Force-included (-include) before the ITK-using files of src/io/ in the clang fuzz build.
// Debian's ITK headers were generated for GCC: itk_compiler_detection.h knows only GNU and stops
// with "#error Unsupported compiler" under clang. Clang implements everything the GNU branch
// enables (C++11/14 features), so the detection runs once here with clang dressed as GCC 12, and
// its include guard keeps every later #include of it a no-op. Nothing else sees the disguise.
#pragma once
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
