// The replaceable assertion handler.
#include <spindle/platform/assert.hpp>

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace spindle {
namespace {

void default_handler(const char* expr, const char* message, const char* file, int line) {
    std::fprintf(stderr, "spindle: assertion failed: %s (%s) at %s:%d\n", message, expr, file, line);
    std::fflush(stderr);
}

std::atomic<AssertHandler> g_handler{&default_handler};

}  // namespace

AssertHandler set_assert_handler(AssertHandler handler) {
    return g_handler.exchange(handler ? handler : &default_handler);
}

void assert_failed(const char* expr, const char* message, const char* file, int line) {
    g_handler.load()(expr, message, file, line);  // may throw (tests)
    std::abort();
}

}  // namespace spindle
