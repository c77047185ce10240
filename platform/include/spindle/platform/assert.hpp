// Internal invariant checks. SPINDLE_ASSERT is on unless NDEBUG (or forced with
// SPINDLE_ENABLE_ASSERTS); SPINDLE_VALIDATE is for O(n) walks and is on in debug and
// sanitizer builds only. Bad *user* input is not an assert: it throws spindle::Error.
#pragma once

namespace spindle {

// Called when an assertion fails. The default prints and aborts; tests may install
// one that throws. Returns the previous handler. Not thread safe: set it at start-up.
using AssertHandler = void (*)(const char* expr, const char* message, const char* file, int line);
AssertHandler set_assert_handler(AssertHandler handler);
[[noreturn]] void assert_failed(const char* expr, const char* message, const char* file, int line);

}  // namespace spindle

#if !defined(NDEBUG) || defined(SPINDLE_ENABLE_ASSERTS)
#define SPINDLE_ASSERT(cond, message)                                              \
    do {                                                                           \
        if (!(cond)) ::spindle::assert_failed(#cond, message, __FILE__, __LINE__); \
    } while (false)
#else
#define SPINDLE_ASSERT(cond, message) \
    do {                              \
        (void)sizeof(cond);           \
    } while (false)
#endif

#if !defined(NDEBUG) || defined(SPINDLE_ENABLE_VALIDATE)
#define SPINDLE_VALIDATE_ENABLED 1
#define SPINDLE_VALIDATE(cond, message) SPINDLE_ASSERT(cond, message)
#else
#define SPINDLE_VALIDATE_ENABLED 0
#define SPINDLE_VALIDATE(cond, message) \
    do {                                \
    } while (false)
#endif
