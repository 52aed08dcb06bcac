// CHECK and DCHECK: invariants inside the library (STYLE.md habit 7, pbrt-v4's util/check.h).
//
// Bad input is not an invariant: io/ and option parsing throw lacuna::Error or FrameError naming
// the file or field, and a front end prints one line. A CHECK states what the code itself
// guarantees (a registry entry has the face the capabilities table granted, a renderer was
// prepared before it renders); when one fails, lacuna has a bug, so it prints where and the
// operands, and aborts: continuing would render a wrong image silently.
//
//   LACUNA_CHECK(cond)           always on
//   LACUNA_CHECK_EQ(a, b) ...    _NE _LT _LE _GT _GE: always on, prints both operands
//   LACUNA_DCHECK(cond) ...      only in builds without NDEBUG (Debug, the sanitizers); in Release
//                                the condition is not evaluated, so a DCHECK may sit on a hot path
//
// Never inside a sample loop's hot path as a CHECK (it is a branch and keeps operands live); use
// a DCHECK there.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace lacuna::detail {

[[noreturn]] inline void check_failed(const char* file, int line, const char* what,
                                      const std::string& operands = {}) {
    std::fprintf(stderr, "lacuna: CHECK failed at %s:%d: %s%s%s\n", file, line, what,
                 operands.empty() ? "" : " ", operands.c_str());
    std::fflush(stderr);
    std::abort();
}

template <class A, class B>
std::string operands(const A& a, const B& b) {
    std::ostringstream s;
    s << "(" << a << " vs " << b << ")";
    return s.str();
}

}  // namespace lacuna::detail

#define LACUNA_CHECK(cond)                                                      \
    do {                                                                        \
        if (!(cond)) ::lacuna::detail::check_failed(__FILE__, __LINE__, #cond); \
    } while (false)

#define LACUNA_CHECK_OP(a, op, b)                                              \
    do {                                                                       \
        const auto& lacuna_check_a_ = (a);                                     \
        const auto& lacuna_check_b_ = (b);                                     \
        if (!(lacuna_check_a_ op lacuna_check_b_))                             \
            ::lacuna::detail::check_failed(                                    \
                __FILE__, __LINE__, #a " " #op " " #b,                         \
                ::lacuna::detail::operands(lacuna_check_a_, lacuna_check_b_)); \
    } while (false)

#define LACUNA_CHECK_EQ(a, b) LACUNA_CHECK_OP(a, ==, b)
#define LACUNA_CHECK_NE(a, b) LACUNA_CHECK_OP(a, !=, b)
#define LACUNA_CHECK_LT(a, b) LACUNA_CHECK_OP(a, <, b)
#define LACUNA_CHECK_LE(a, b) LACUNA_CHECK_OP(a, <=, b)
#define LACUNA_CHECK_GT(a, b) LACUNA_CHECK_OP(a, >, b)
#define LACUNA_CHECK_GE(a, b) LACUNA_CHECK_OP(a, >=, b)

#ifdef NDEBUG
// Not evaluated, but still compiled (so a DCHECK cannot rot): `false && (cond)`.
#define LACUNA_DCHECK(cond)    \
    do {                       \
        if (false && (cond)) { \
        }                      \
    } while (false)
#define LACUNA_DCHECK_OP(a, op, b) \
    do {                           \
        if (false && ((a)op(b))) { \
        }                          \
    } while (false)
#else
#define LACUNA_DCHECK(cond) LACUNA_CHECK(cond)
#define LACUNA_DCHECK_OP(a, op, b) LACUNA_CHECK_OP(a, op, b)
#endif
#define LACUNA_DCHECK_EQ(a, b) LACUNA_DCHECK_OP(a, ==, b)
#define LACUNA_DCHECK_NE(a, b) LACUNA_DCHECK_OP(a, !=, b)
#define LACUNA_DCHECK_LT(a, b) LACUNA_DCHECK_OP(a, <, b)
#define LACUNA_DCHECK_LE(a, b) LACUNA_DCHECK_OP(a, <=, b)
#define LACUNA_DCHECK_GT(a, b) LACUNA_DCHECK_OP(a, >, b)
#define LACUNA_DCHECK_GE(a, b) LACUNA_DCHECK_OP(a, >=, b)
